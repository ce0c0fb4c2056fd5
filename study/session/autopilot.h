#pragma once
// A simulated participant for end-to-end tests and demos. It decides *which* key to
// press and *when* (seeded, human-like delays); the runner sends each key as a real X
// key event through XTest (x_keyboard.h), so it reaches GLFW exactly as a keyboard's.
// An adjust trial's match may be turned with the mouse wheel or a drag instead
// (--autopilot-adjust), sent as X pointer events the same way.
// GL-free and X-free, so its timing model is unit-tested. It answers forced choices as a
// simulated observer with a known perceptual scale.
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "study/session/layout.h"
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
    // Where the match is in the window (pixels), filled in by the runner from its
    // layout: a drag must start on it.
    std::optional<Rect> match;
};

// How a seeded participant turns an adjust trial's match (--autopilot-adjust).
enum class AdjustBy { keys, wheel, drag };
// "keys", "wheel" or "drag"; std::nullopt for anything else.
std::optional<AdjustBy> parse_adjust_by(const std::string& name);

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
                      // "R"; "Shift+Left", "Shift+Right" (an adjustment's fine steps);
                      // pointer events (is_pointer_event): "WheelUp", "WheelDown" (one
                      // notch, +1 / -1), "Press:X,Y" (the pointer to window pixel X,Y,
                      // button 1 down), "Move:X,Y" (the pointer there), "Release"
};

// Whether an event name is the pointer's (the wheel, a drag), not a key.
bool is_pointer_event(const std::string& name);

// The arrow keys that take an adjust trial's match from view.value to (as near as the
// fine steps allow) `goal`: coarse steps first, then fine ones ("Right", "Left",
// "Shift+Right", "Shift+Left"), on the view's scale; at most 1000 keys.
std::vector<std::string> adjust_keys(const AdjustView& view, double goal);
// The same with the wheel: whole notches toward `goal`, one coarse step each
// ("WheelUp" moves the value up), then the fine steps left as Shift + arrows.
std::vector<std::string> adjust_wheel(const AdjustView& view, double goal);
// The same with a drag across view.match, whose width spans the range on the scale:
// "Move:X,Y" (onto the match), "Press:X,Y", "Move:X+DX,Y", "Release" with DX the
// goal's distance in whole pixels (the stroke centred on the match, at its middle row;
// none when DX is 0), then the
// steps left after it as arrows (Shift for fine). Without view.match: adjust_keys.
std::vector<std::string> adjust_drag(const AdjustView& view, double goal);

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
    // How adjust trials' matches are turned (default: keys).
    void set_adjust_by(AdjustBy by) { adjust_by_ = by; }

    // A seeded participant's keys due at `now_ns` for the screen shown; call once per
    // frame. At most one pointer event is returned per call (later ones wait for the
    // next): ImGui reads the pointer once per frame, so two notches in one frame would
    // be one move of two steps, and a drag's move and release together would drop the
    // move. A key after a pointer event waits two calls: the runner applies pointer
    // events while drawing the frame after, keys before drawing. (A script's keys are
    // not due here: see script().)
    // A screen still shown kPatienceNs after its last key (a key lost on the way, as a
    // person's sometimes is) is answered again, as a person would press again: once
    // per kPatienceNs, counted in presses_again().
    std::vector<std::string> due(int64_t now_ns, const ScreenView& view);
    static constexpr int64_t kPatienceNs = 5'000'000'000;
    int presses_again() const { return presses_again_; }
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
    AdjustBy adjust_by_ = AdjustBy::keys;
    int planned_serial_ = -1;
    int64_t last_event_ns_ = 0;  // when the last key or pointer event was due
    int presses_again_ = 0;
    int frames_since_pointer_ = 2;  // due() calls since the last pointer event
    std::vector<std::pair<double, std::string>> script_;  // (delay ms, key)
    std::vector<ScheduledKey> queue_;
};

}  // namespace lucent::study
