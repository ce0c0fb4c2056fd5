// lucent power: the power of a planned study's tests by seeded simulation (with Monte
// Carlo errors and the noncentral-F closed form where it exists), and the smallest number
// of participants that reaches a target power. With --model lmm|clmm, the power of a
// design in which participants and stimuli are both sampled, by pictures per level.
#include <iomanip>
#include <iostream>
#include <sstream>

#include "analysis/models/rating_model.h"
#include "analysis/simulate/crossed_power.h"
#include "analysis/simulate/power.h"
#include "app/commands.h"

namespace lucent::app {
namespace {

struct PowerArgs {
    analysis::PowerSpec spec;
    std::string design = "within";
    double target = 0.0;  // 0: no search
    int max_participants = 500;
    std::string model = "anova";
    int stimuli = 6;                // per level (--model lmm|clmm)
    std::vector<int> stimuli_list;  // a table over pictures per level
    double stimulus_sd = 0.5;
};

std::string estimate_text(const analysis::PowerEstimate& e) {
    std::ostringstream out;
    out << std::fixed << std::setprecision(3) << e.power << " +/- " << e.mc_error;
    return out.str();
}

void print_row(std::ostream& out, const std::string& label,
               const analysis::PowerEstimate& e) {
    out << std::left << std::setw(34) << label << estimate_text(e) << "\n";
}

void print_result(const analysis::PowerResult& r, std::ostream& out) {
    const analysis::PowerSpec& s = r.spec;
    out << "design " << analysis::design_name(s.design) << ", " << s.participants
        << (s.design == analysis::Design::Between ? " participants per level"
                                                  : " participants")
        << ", " << s.level_means.size() << " levels, alpha " << s.alpha << ", "
        << s.simulations << " simulations (seed " << s.seed << ")"
        << (s.likert ? ", responses rounded to 1..7" : "") << "\n";
    out << std::left << std::setw(34) << "test"
        << "power +/- MC error\n";
    if (r.rm_anova) {
        print_row(out, "repeated-measures ANOVA", *r.rm_anova);
        print_row(out, "  with Greenhouse-Geisser p", *r.rm_anova_gg);
    }
    print_row(out, "one-way ANOVA", r.one_way_anova);
    print_row(out, "any pair (" + r.pairwise_test + ")", r.any_pair);
    for (const analysis::PairPower& p : r.pairs)
        print_row(out, "  level " + p.level_a + " vs " + p.level_b, p.estimate);
    if (r.closed_form) {
        std::ostringstream value;
        value << std::fixed << std::setprecision(4) << *r.closed_form;
        out << "closed form (noncentral F) of the "
            << (r.rm_anova ? "repeated-measures" : "one-way") << " ANOVA: " << value.str()
            << "\n";
    } else {
        out << "closed form: none for responses rounded to a rating scale\n";
    }
}

void print_crossed_header(const analysis::CrossedPowerSpec& s, std::ostream& out) {
    out << "model " << s.model << " (rating ~ level + (1 | "
        << "participant) + (1 | stimulus)), " << s.participants << " participants, "
        << s.level_means.size() << " levels, participant SD " << s.participant_sd
        << ", stimulus SD " << s.stimulus_sd << ", residual SD " << s.residual_sd
        << ", alpha " << s.alpha << ", " << s.simulations << " simulations (seed "
        << s.seed << ")"
        << (s.likert || analysis::find_rating_model(s.model)->rounds_to_scale
                ? ", responses rounded to 1..7"
                : "")
        << "\n";
    out << std::left << std::setw(18) << "stimuli/level" << std::setw(22) << "mixed model"
        << std::setw(34) << "RM ANOVA of participant means"
        << "closed form (mixed)\n";
}

void print_crossed_row(const analysis::CrossedPowerResult& r, std::ostream& out) {
    std::ostringstream closed;
    if (r.closed_form)
        closed << std::fixed << std::setprecision(4) << *r.closed_form;
    else
        closed << "none (rounded responses)";
    out << std::left << std::setw(18) << r.spec.stimuli_per_level << std::setw(22)
        << estimate_text(r.model_test) << std::setw(34) << estimate_text(r.by_participant)
        << closed.str();
    if (r.failed_fits > 0) out << "  (" << r.failed_fits << " fits gave no p)";
    out << "\n";
}

// --model lmm|clmm: one row per number of pictures per level.
int run_crossed_power(const PowerArgs& args) {
    using namespace lucent::analysis;
    CrossedPowerSpec spec;
    spec.model = parse_rating_model(args.model, "--model");
    spec.participants = args.spec.participants;
    spec.level_means = args.spec.level_means;
    spec.participant_sd = args.spec.participant_sd;
    spec.stimulus_sd = args.stimulus_sd;
    spec.residual_sd = args.spec.residual_sd;
    spec.alpha = args.spec.alpha;
    spec.simulations = args.spec.simulations;
    spec.seed = args.spec.seed;
    spec.likert = args.spec.likert;
    const std::vector<int> sizes =
        args.stimuli_list.empty() ? std::vector<int>{args.stimuli} : args.stimuli_list;
    for (int m : sizes) {
        spec.stimuli_per_level = m;
        check_crossed_power_spec(spec);
    }
    print_crossed_header(spec, std::cout);
    for (int m : sizes) {
        spec.stimuli_per_level = m;
        const CrossedPowerResult result =
            estimate_crossed_power(spec, [m](int done, int total) {
                if (done % 50 == 0 || done == total)
                    std::cerr << "stimuli/level " << m << ": " << done << "/" << total
                              << " simulated studies\r" << (done == total ? "\n" : "")
                              << std::flush;
            });
        print_crossed_row(result, std::cout);
    }
    std::cout
        << "The RM ANOVA of participant means ignores the stimulus variance: with "
           "stimulus SD > 0 its rate overstates power and, with equal means, rejects "
           "more often than alpha.\n";
    return kExitOk;
}

int run_power(PowerArgs args) {
    using namespace lucent::analysis;
    try {
        if (parse_rating_model(args.model, "--model") != kOneWayTests)
            return run_crossed_power(args);
        args.spec.design = args.design == "between" ? Design::Between : Design::Within;
        check_power_spec(args.spec);
        if (args.target > 0.0) {
            std::cerr << "searching participants in [2, " << args.max_participants
                      << "] for power " << args.target << "...\n";
            const SampleSize size =
                smallest_sample(args.spec, args.target, args.max_participants);
            print_result(size.at, std::cout);
            if (size.participants)
                std::cout << "smallest participants reaching power " << args.target
                          << ": " << *size.participants << " (" << size.evaluations
                          << " sizes simulated)\n";
            else
                std::cout << "power " << args.target << " is not reached with "
                          << args.max_participants << " participants\n";
            return kExitOk;
        }
        print_result(estimate_power(args.spec), std::cout);
        return kExitOk;
    } catch (const analysis::InputError& e) {
        std::cerr << "lucent power: " << e.what() << "\n";
        return kExitUsage;
    }
}

}  // namespace

void register_power(CLI::App& app, int& exit_code) {
    auto args = std::make_shared<PowerArgs>();
    auto* cmd = app.add_subcommand(
        "power",
        "Power of a planned design's ANOVA, repeated-measures ANOVA and pairwise tests "
        "by "
        "seeded simulation, and the smallest number of participants for a target power");
    cmd->add_option("--design", args->design,
                    "between (participants per level) or within")
        ->check(CLI::IsMember({"between", "within"}))
        ->capture_default_str();
    cmd->add_option("--participants", args->spec.participants,
                    "Participants (within: in all; between: per level)")
        ->capture_default_str();
    cmd->add_option("--means", args->spec.level_means,
                    "Expected mean response per level, e.g. 3.5,4,4.6")
        ->delimiter(',')
        ->required();
    cmd->add_option("--participant-sd", args->spec.participant_sd,
                    "SD of participants' offsets")
        ->capture_default_str();
    cmd->add_option("--residual-sd", args->spec.residual_sd, "SD of a single response")
        ->capture_default_str();
    cmd->add_option("--alpha", args->spec.alpha, "Significance level")
        ->capture_default_str();
    cmd->add_option("--simulations", args->spec.simulations, "Simulated studies per size")
        ->capture_default_str();
    cmd->add_option("--seed", args->spec.seed, "Random seed")->capture_default_str();
    cmd->add_flag("--likert", args->spec.likert,
                  "Round and clamp responses to the 1..7 scale (no closed form then)");
    std::string simulated;
    for (const analysis::RatingModelSpec* m : analysis::rating_models())
        if (m->crossed_p) simulated += (simulated.empty() ? "" : " / ") + m->name;
    cmd->add_option("--model", args->model,
                    "anova (the one-way tests, stimuli fixed), or " + simulated +
                        ": the mixed model of a design with participants and stimuli "
                        "both sampled")
        ->capture_default_str();
    cmd->add_option("--stimuli", args->stimuli,
                    "Pictures per level (--model lmm|clmm); every participant rates all")
        ->capture_default_str();
    cmd->add_option("--stimuli-list", args->stimuli_list,
                    "Pictures per level to tabulate, e.g. 2,4,8,16 (--model lmm|clmm)")
        ->delimiter(',');
    cmd->add_option("--stimulus-sd", args->stimulus_sd, "SD of stimuli's offsets")
        ->capture_default_str();
    cmd->add_option(
        "--target", args->target,
        "Find the smallest participants whose primary test reaches this power");
    cmd->add_option("--max-participants", args->max_participants,
                    "Upper end of the search")
        ->capture_default_str();
    cmd->callback([args, &exit_code] { exit_code = run_power(*args); });
}

}  // namespace lucent::app
