#pragma once
// The session runner: consent, instructions, practice, rated trials with breaks,
// debrief, in a full-screen window; every trial's ratings committed before the next.
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

#include "study/protocol.h"
#include "study/session/autopilot.h"
#include "study/session/session_flow.h"
#include "study/session/stimulus_source.h"
#include "study/simulated_observer.h"

namespace lucent::study {

struct RunOptions {
    Protocol protocol;
    std::string db_path;
    std::string participant;
    bool windowed = false;  // a 1280x1024 window instead of full screen
    int monitor = 0;
    bool resume = false;           // continue the participant's unfinished session
    std::optional<uint64_t> seed;  // session seed (default: random, stored)
    std::string autopilot;         // "" (a person), a seed, or a script file
    double autopilot_speed = 1.0;
    // How a seeded autopilot answers forced choices (simulated_observer.h).
    ObserverModel autopilot_observer;
    // How it answers staircases (a known psychometric function) and adjustments (a known
    // match bias).
    DetectionObserver autopilot_detection;
    MatchObserver autopilot_match;
    // How it turns an adjust trial's match: arrows, the wheel or a drag (then fine
    // arrows).
    AdjustBy autopilot_adjust = AdjustBy::keys;
    std::string screenshot_path;  // save the first trial screen as PNG (tests)
    std::string key_trace_path;   // each key press's X event time and stamp (tests)
};

// Outcome: RunResult (session_flow.h), mapped to exit codes by the caller. A participant
// who already completed the study is refused (UsageError), with or without --resume.
RunResult run_session(const RunOptions& options, StimulusRenderer& stimuli,
                      std::ostream& log);

}  // namespace lucent::study
