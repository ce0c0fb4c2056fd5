// lucent simulate: writes a seeded synthetic study (long CSV) from a latent normal model,
// so the analysis pipeline can be exercised without a lab.
#include <iostream>

#include "analysis/simulate/simulate.h"
#include "app/commands.h"
#include "common/output_file.h"

namespace lucent::app {

void register_simulate(CLI::App& app, int& exit_code) {
    auto spec = std::make_shared<analysis::SimulationSpec>();
    auto out = std::make_shared<std::string>();
    auto* cmd = app.add_subcommand(
        "simulate",
        "Write a seeded synthetic study (long CSV of 7-point ratings from a latent "
        "normal model) for 'lucent analyze'");
    cmd->add_option("--out", *out, "CSV file to write")->required();
    cmd->add_option("--participants", spec->participants, "Participants")
        ->capture_default_str();
    cmd->add_option("--stimuli-per-level", spec->stimuli_per_level, "Stimuli per level")
        ->capture_default_str();
    cmd->add_option("--questions", spec->questions, "Question names")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--factor", spec->factor, "Factor name")->capture_default_str();
    cmd->add_option(
           "--effects", spec->level_effects,
           "Latent effect per level in noise-SD units, e.g. 0,0.5,1 (one per level)")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--participant-sd", spec->participant_sd, "SD of participant offsets")
        ->capture_default_str();
    cmd->add_option("--noise-sd", spec->noise_sd, "SD of per-rating noise")
        ->capture_default_str();
    cmd->add_option("--stimulus-sd", spec->stimulus_sd,
                    "SD of each stimulus's own offset (what a mixed model's stimulus "
                    "term estimates)")
        ->capture_default_str();
    cmd->add_option("--seed", spec->seed, "Random seed")->capture_default_str();
    cmd->callback([spec, out, &exit_code] {
        try {
            const analysis::LongTable table = analysis::simulate_study(*spec);
            // Replaces an earlier simulated CSV, never a database; atomically.
            common::check_output_file(*out, {}, true);
            common::write_file_atomically(*out, true, [&](std::ostream& file) {
                analysis::write_long_csv(file, table);
            });
            std::cerr << "wrote " << table.rows.size() << " ratings to " << *out << "\n";
            exit_code = kExitOk;
        } catch (const analysis::InputError& e) {
            std::cerr << "lucent simulate: " << e.what() << "\n";
            exit_code = kExitUsage;
        } catch (const common::OutputError& e) {
            std::cerr << "lucent simulate: " << e.what() << "\n";
            exit_code = kExitUsage;
        }
    });
}

}  // namespace lucent::app
