#pragma once
// A simulated participant for end-to-end tests and demos. It decides *which* key to
// press and *when* (seeded, human-like delays); the runner sends each key as a real X
// key event through XTest (x_keyboard.h), so it reaches GLFW exactly as a keyboard's.
// GL-free and X-free, so its timing model is unit-tested. It answers forced choices as a
// simulated observer with a known perceptual scale.
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "study/simulated_observer.h"

namespace lucent::study {

// An adjust trial as the simulated participant sees it: the match's value now, what
// the keys do, and the value its match centres on: the target's value of the knob when
// the target is drawn by the match's technique, else the match stimulus's own value
// (SessionFlow::adjust_view).
struct AdjustView {
    double value = 0;
    double lo = 0, hi = 1;
    double step = 0.1, fine_step = 0.01;
    bool log_scale = false;
    std::optional<double> target;
};

// A staircase trial: the delta shown, the place of the comparison (the right answer)
// and the number of answers (2 or 3). The simulated observer detects the delta with its
// psychometric function (DetectionObserver).
struct StaircaseView {
    double delta = 0;
    int comparison_place = 1;
    int answers = 2;
};

// What is on screen, as far as a participant can tell.
struct ScreenView {
    enum class Kind { Text, Rating, Choice, Blank, Pause, Adjust, Staircase };
    Kind kind = Kind::Blank;
    int serial = 0;           // increases whenever a new screen appears
    std::vector<int> points;  // rating screens: each question's scale length
    bool is_catch = false;    // catch trials: the prompt asks for `expected`
    int expected = 0;
    ChoiceStimuli choice;  // forced choices: what the observer judges
    AdjustView adjust;
    StaircaseView staircase;
};

struct ScheduledKey {
    int64_t at_ns = 0;
    std::string key;  // "1".."9", "Enter", "Escape", "Left", "Right", "Up", "Down", "Q",
                      // "R"; "Shift+Left", "Shift+Right" (an adjustment's fine steps)
};

// The arrow keys that take an adjust trial's match from view.value to (as near as the
// fine steps allow) `goal`: coarse steps first, then fine ones ("Right", "Left",
// "Shift+Right", "Shift+Left"), on the view's scale; at most 1000 keys.
std::vector<std::string> adjust_keys(const AdjustView& view, double goal);

class Autopilot {
public:
    // Seeded participant; `speed` divides every delay (1 = human-like, 20 = fast tests).
    // Forced choices are answered by `observer` (simulated_observer.h), so a fitted
    // scale can be checked against the observer's.
    static Autopilot from_seed(uint64_t seed, double speed = 1.0,
                               const ObserverModel& observer = {});
    // A script: one "DELAY_MS KEY" per line (# comments), played in order from the
    // session's first frame, whatever is on screen: the runner hands it to the X server
    // at once (XKeyboard::play). Throws std::runtime_error naming file:line.
    static Autopilot from_file(const std::string& path);
    // The argument of --autopilot: digits are a seed, anything else a script file.
    static Autopilot from_argument(const std::string& argument, double speed,
                                   const ObserverModel& observer = {});

    // The observers that answer staircases (a known psychometric function) and
    // adjustments (a known match bias); defaults: DetectionObserver{}, MatchObserver{}.
    void set_threshold_observers(const DetectionObserver& detection,
                                 const MatchObserver& match) {
        detection_ = detection;
        match_ = match;
    }

    // A seeded participant's keys due at `now_ns` for the screen shown; call once per
    // frame. (A script's keys are not due here: see script().)
    std::vector<std::string> due(int64_t now_ns, const ScreenView& view);
    bool scripted() const { return scripted_; }
    // A script's (delay ms after the previous key, key) lines, for XKeyboard::play.
    const std::vector<std::pair<double, std::string>>& script() const { return script_; }

private:
    void plan_screen(int64_t now_ns, const ScreenView& view);
    double delay_ms(double median_ms);  // log-normal around a median, divided by speed

    bool scripted_ = false;
    std::mt19937_64 rng_;
    double speed_ = 1.0;
    ObserverModel observer_;
    DetectionObserver detection_;
    MatchObserver match_;
    int planned_serial_ = -1;
    std::vector<std::pair<double, std::string>> script_;  // (delay ms, key)
    std::vector<ScheduledKey> queue_;
};

}  // namespace lucent::study
