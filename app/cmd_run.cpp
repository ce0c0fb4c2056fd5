// lucent run: a participant session from a protocol file or the built-in preset.
#include <iostream>
#include <sstream>

#include "app/analysis_plan.h"
#include "app/commands.h"
#include "study/protocol.h"
#include "study/session/live_stimuli.h"
#include "study/session/runner.h"
#include "study/session/session_flow.h"
#include "study/session/stimulus_source.h"
#include "study/sqlite/database.h"
#include "study/trial_plan.h"

namespace lucent::app {
namespace {

// The autopilot's observer unless --autopilot-observer says otherwise: the model's own
// default (simulated_observer.h), so the two never differ.
std::string default_observer() {
    const study::ObserverModel m;
    std::ostringstream text;
    text << m.exponent << "," << m.sigma;
    return text.str();
}

struct RunArgs {
    std::string protocol_file;
    std::string preset;
    std::string images_dir;
    int64_t seed = -1;
    std::string observer = default_observer();
    std::string detection;  // "" = DetectionObserver{}
    std::string match;      // "" = MatchObserver{}
    std::string adjust = "keys";
    study::RunOptions options;
};

int run_command(RunArgs& args) {
    study::RunOptions& o = args.options;
    if (args.protocol_file.empty() == args.preset.empty()) {
        std::cerr << "lucent run: give a PROTOCOL.toml or --preset NAME (exactly one)\n";
        return kExitUsage;
    }
    try {
        o.autopilot_observer = study::ObserverModel::parse(args.observer);
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent run: --autopilot-observer: " << e.what() << "\n";
        return kExitUsage;
    }
    try {
        if (!args.detection.empty())
            o.autopilot_detection = study::DetectionObserver::parse(args.detection);
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent run: --autopilot-detection: " << e.what() << "\n";
        return kExitUsage;
    }
    try {
        if (!args.match.empty())
            o.autopilot_match = study::MatchObserver::parse(args.match);
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent run: --autopilot-match: " << e.what() << "\n";
        return kExitUsage;
    }
    // CLI::IsMember has checked the name.
    o.autopilot_adjust =
        study::parse_adjust_by(args.adjust).value_or(study::AdjustBy::keys);
    try {
        o.protocol = args.preset.empty() ? study::load_protocol_file(args.protocol_file)
                                         : study::builtin_protocol(args.preset);
        check_analysis_plan(o.protocol);  // a plan naming no analysis fails here, early
        if (args.seed >= 0) o.seed = static_cast<uint64_t>(args.seed);
        study::plan_trials(o.protocol, 0,
                           0);  // impossible randomisation fails here, early
        study::LiveOrPrerenderedStimuli stimuli(args.images_dir);
        switch (study::run_session(o, stimuli, std::cerr)) {
            case study::RunResult::Completed:
            case study::RunResult::SavedAndQuit:
            case study::RunResult::Declined:
                return kExitOk;
            case study::RunResult::UsageError:
                return kExitUsage;
            case study::RunResult::Failure:
                return kExitFailure;
        }
    } catch (const study::ProtocolError& e) {
        std::cerr << "lucent run: " << e.what() << "\n";
        return kExitUsage;
    } catch (const study::PlanError& e) {
        std::cerr << "lucent run: " << e.what() << "\n";
        return kExitUsage;
    } catch (const study::StoreError& e) {
        std::cerr << "lucent run: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::exception& e) {
        std::cerr << "lucent run: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitFailure;
}

}  // namespace

void register_run(CLI::App& app, int& exit_code) {
    auto args = std::make_shared<RunArgs>();
    auto* cmd = app.add_subcommand(
        "run",
        "Run a participant session full-screen (ratings stored in an SQLite file or a "
        "PostgreSQL study server)");
    cmd->add_option("protocol", args->protocol_file, "Study protocol file (TOML)");
    cmd->add_option("--preset", args->preset, "Built-in protocol instead of a file")
        ->check(CLI::IsMember(study::builtin_protocol_names()));
    cmd->add_option("--db", args->options.db_path,
                    "Study database: FILE.db (created when absent) or "
                    "postgresql://USER@HOST[:PORT]/DBNAME (after 'lucent store init')")
        ->required();
    cmd->add_option("--participant", args->options.participant,
                    "Participant code, e.g. P07")
        ->required();
    cmd->add_flag("--windowed", args->options.windowed,
                  "A 1280x1024 window instead of full screen");
    cmd->add_option("--monitor", args->options.monitor, "Monitor index for full screen")
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag("--resume", args->options.resume,
                  "Continue the participant's unfinished session");
    cmd->add_option(
        "--images", args->images_dir,
        "Directory of pre-rendered images named <stimulus id>.png|.tif|.exr (e.g. from "
        "'lucent render --preset thesis --out DIR'); others render live");
    cmd->add_option("--seed", args->seed,
                    "Session seed (default: random; stored either way)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--autopilot", args->options.autopilot,
                    "Simulated participant: a SEED, or a FILE of 'DELAY_MS KEY' lines");
    cmd->add_option("--autopilot-speed", args->options.autopilot_speed,
                    "Divide the autopilot's human-like delays by this factor")
        ->check(CLI::PositiveNumber);
    cmd->add_option(
           "--autopilot-observer", args->observer,
           "How a seeded autopilot answers forced choices: EXPONENT,SIGMA[,LAPSE] "
           "(scale psi = x^EXPONENT over the block's series, decision noise SIGMA "
           "in units of its range, a share LAPSE of random choices)")
        ->capture_default_str();
    cmd->add_option("--autopilot-detection", args->detection,
                    "How a seeded autopilot answers staircase trials: "
                    "THRESHOLD,SPREAD[,LAPSE] (a cumulative Gaussian in the delta, "
                    "guessing when it does not see it)");
    cmd->add_option(
        "--autopilot-match", args->match,
        "How a seeded autopilot settles an adjustment: BIAS,NOISE[,log] "
        "(target + BIAS + N(0, NOISE^2), on the knob's logarithm with 'log')");
    cmd->add_option("--autopilot-adjust", args->adjust,
                    "How a seeded autopilot turns an adjust trial's match: keys (arrows, "
                    "Shift for fine steps), wheel (one notch a coarse step) or drag "
                    "(across the match, whose width spans the range), the last two "
                    "finished with Shift + arrows")
        ->check(CLI::IsMember({"keys", "wheel", "drag"}))
        ->capture_default_str();
    cmd->add_option(
        "--screenshot", args->options.screenshot_path,
        "Save the first trial screen (rating, choice, adjust or staircase) as a PNG "
        "(for tests)");
    cmd->add_option(
        "--key-trace", args->options.key_trace_path,
        "Write each key press as 'X_EVENT_MS RECEIPT_NS STAMP_NS' (for tests)");
    cmd->callback([args, &exit_code] { exit_code = run_command(*args); });
}

}  // namespace lucent::app
