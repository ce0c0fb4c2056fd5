#pragma once
// A protocol with an adjust block and a staircase block for the matching and threshold
// tests, and the rows a simulated participant gives it.
#include <random>
#include <string>
#include <vector>

#include "analysis/data/matching_table.h"
#include "study/adaptive/staircase_block.h"
#include "study/protocol.h"
#include "study/simulated_observer.h"

namespace lucent::analysis::testing {

// Targets: "front" differs from the match in backlight only (a constancy index),
// "two_factors" in backlight and diffuse_weight (none), "picture" is a picture. The
// staircase block runs two up/down staircases and a QUEST on "std1" (thickness exponent
// 2) with deltas in [0, 3].
inline const char* kProtocol = R"toml(
[study]
name = "matching_analysis"

[[stimuli]]
id = "front"
technique = "empirical"
params = { thickness_exponent = 2, backlight = 1.2 }

[[stimuli]]
id = "two_factors"
technique = "empirical"
params = { thickness_exponent = 2, backlight = 1.2, diffuse_weight = 0.5 }

[[stimuli]]
id = "match"
technique = "empirical"
params = { thickness_exponent = 1, backlight = 0.6 }

[[stimuli]]
id = "picture"
image = "picture.png"

[[stimuli]]
id = "std1"
technique = "empirical"
params = { thickness_exponent = 2 }

[[blocks]]
id = "m"
task = "adjust"
stimuli = ["front", "two_factors", "picture"]
match = "match"
knob = "thickness_exponent"
range = [0, 10]
question = "Turn the right object until it looks like the left one."

[[blocks]]
id = "j"
task = "staircase"
stimuli = ["std1"]
knob = "thickness_exponent"
question = "Which looks more translucent?"

[[blocks.staircases]]
id = "up"
start = 2.5
step_sizes = [0.4, 0.2, 0.1]
n_trials = 80
max_delta = 3
max_trials = 80

[[blocks.staircases]]
id = "low"
start = 0.3
step_sizes = [0.4, 0.2, 0.1]
n_trials = 80
max_delta = 3
max_trials = 80

[[blocks.staircases]]
id = "q"
method = "quest"
start = 1.5
start_sd = 1
n_trials = 80
max_delta = 3
max_trials = 80
)toml";

inline study::Protocol protocol() {
    return study::parse_protocol(kProtocol, "matching.toml");
}

// A participant's staircase trials in `block_id`: the block's procedures interleaved in
// rounds (a random order each round), each answered by `observer`, the comparison's
// place drawn at random.
inline std::vector<StaircaseRow> simulate_staircases(
    const study::Protocol& p, const std::string& participant,
    const study::DetectionObserver& observer, std::mt19937_64& rng,
    const std::string& block_id = "j") {
    const study::Block& block = *p.find_block(block_id);
    study::adaptive::StaircaseBlock procedures(block);
    const double guess = study::adaptive::guess_rate(block);
    std::vector<StaircaseRow> rows;
    int position = 0;
    for (;;) {
        std::vector<std::string> running;
        for (const std::string& label : procedures.labels())
            if (!procedures.finished(label)) running.push_back(label);
        if (running.empty()) break;
        std::shuffle(running.begin(), running.end(), rng);
        for (const std::string& label : running) {
            const double delta = procedures.propose(label).intensity;
            const bool correct = study::simulated_detection(observer, delta, guess, rng);
            procedures.answer(label, correct);
            StaircaseRow r;
            r.participant = participant;
            r.session = participant + "-s";
            r.trial = position++;
            r.block = block_id;
            r.standard = label.substr(0, label.find('/'));
            r.staircase = label;
            r.intensity = delta;
            const int places = block.answers();
            r.expected = 1 + static_cast<int>(rng() % places);
            r.choice = correct ? r.expected : 1 + r.expected % places;
            r.correct = correct;
            rows.push_back(r);
        }
    }
    return rows;
}

inline MatchRow match_row(const std::string& participant, const std::string& target,
                          double value) {
    MatchRow r;
    r.participant = participant;
    r.session = participant + "-s";
    r.block = std::string("m");
    r.target = target;
    r.match = std::string("match");
    r.knob = std::string("thickness_exponent");
    r.start_value = 5;
    r.final_value = value;
    r.rt_ms = 1000;
    return r;
}

}  // namespace lucent::analysis::testing
