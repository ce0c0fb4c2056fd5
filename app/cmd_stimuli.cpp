// lucent stimuli report DIR: contact sheet, perceptual differences between levels and
// image statistics of a rendered stimulus set (stimuli/set_report/set_report.h).
#include <memory>

#include "app/commands.h"
#include "stimuli/set_report/set_report.h"

namespace lucent::app {

void register_stimuli(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("stimuli", "Check a rendered stimulus set");
    cmd->require_subcommand(1);
    struct Args {
        std::string directory;
        double min_delta_e = 3.0;
    };
    auto args = std::make_shared<Args>();
    auto* report = cmd->add_subcommand(
        "report",
        "Write DIR/report.html and DIR/contact-sheet.png: every stimulus as a thumbnail, "
        "Delta E00 and SSIM between the levels of each series, image statistics");
    report
        ->add_option("dir", args->directory,
                     "output folder of 'lucent render CONFIG --out DIR'")
        ->required();
    report->add_option(
        "--min-delta-e", args->min_delta_e,
        "warn for pairs of levels whose mean Delta E00 is below this (default 3)");
    report->callback([args, &exit_code] {
        stimuli::SetReportOptions options;
        options.min_delta_e = args->min_delta_e;
        exit_code = stimuli::run_stimuli_report(args->directory, options);
    });
}

}  // namespace lucent::app
