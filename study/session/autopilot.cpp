#include "study/session/autopilot.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lucent::study {
namespace {

const std::set<std::string> kKeys = {"1",     "2",  "3",    "4",     "5",      "6",
                                     "7",     "8",  "9",    "Enter", "Escape", "Left",
                                     "Right", "Up", "Down", "Q",     "R"};

// A value's place on the view's scale (clamped into the range first).
double on_scale(const AdjustView& view, double v) {
    v = std::clamp(v, view.lo, view.hi);
    return view.log_scale ? std::log10(v) : v;
}

bool plannable(const AdjustView& view, double goal) {
    return std::isfinite(goal) && view.step > 0 && view.fine_step > 0;
}

// Coarse steps (`up` / `down`, one each) then fine ones (Shift + arrows) over
// `distance` on the scale; at most 1000 in all.
void append_steps(std::vector<std::string>& out, const AdjustView& view, double distance,
                  const char* up, const char* down) {
    const bool rising = distance >= 0;
    const double coarse = std::floor(std::abs(distance) / view.step);
    const double fine =
        std::round((std::abs(distance) - coarse * view.step) / view.fine_step);
    for (int i = 0; i < coarse && out.size() < 1000; ++i)
        out.push_back(rising ? up : down);
    for (int i = 0; i < fine && out.size() < 1000; ++i)
        out.push_back(rising ? "Shift+Right" : "Shift+Left");
}

std::string pixel_event(const char* name, int x, int y) {
    return std::string(name) + ":" + std::to_string(x) + "," + std::to_string(y);
}

}  // namespace

std::optional<AdjustBy> parse_adjust_by(const std::string& name) {
    if (name == "keys") return AdjustBy::keys;
    if (name == "wheel") return AdjustBy::wheel;
    if (name == "drag") return AdjustBy::drag;
    return std::nullopt;
}

bool is_pointer_event(const std::string& name) {
    return name == "WheelUp" || name == "WheelDown" || name == "Release" ||
           name.rfind("Press:", 0) == 0 || name.rfind("Move:", 0) == 0;
}

std::vector<std::string> adjust_keys(const AdjustView& view, double goal) {
    std::vector<std::string> keys;
    if (!plannable(view, goal)) return keys;
    append_steps(keys, view, on_scale(view, goal) - on_scale(view, view.value), "Right",
                 "Left");
    return keys;
}

std::vector<std::string> adjust_wheel(const AdjustView& view, double goal) {
    std::vector<std::string> events;
    if (!plannable(view, goal)) return events;
    append_steps(events, view, on_scale(view, goal) - on_scale(view, view.value),
                 "WheelUp", "WheelDown");
    return events;
}

std::vector<std::string> adjust_drag(const AdjustView& view, double goal) {
    const double low = on_scale(view, view.lo), high = on_scale(view, view.hi);
    if (!view.match || view.match->width <= 0 || !(high > low))
        return adjust_keys(view, goal);
    std::vector<std::string> events;
    if (!plannable(view, goal)) return events;
    const Rect& m = *view.match;
    const double from = on_scale(view, view.value), to = on_scale(view, goal);
    const long dx = std::lround((to - from) / (high - low) * m.width);
    if (dx != 0) {
        // Centred on the match so both ends stay on it; the press must be on it. The
        // pointer gets there a frame before the press: the runner drags by the
        // pointer's moves since the last frame, the press's frame included.
        const int x0 = std::clamp(m.x + static_cast<int>((m.width - dx) / 2), m.x,
                                  m.x + m.width - 1);
        const int y = m.y + m.height / 2;
        events.push_back(pixel_event("Move", x0, y));
        events.push_back(pixel_event("Press", x0, y));
        events.push_back(pixel_event("Move", x0 + static_cast<int>(dx), y));
        events.push_back("Release");
    }
    // Where the drag leaves the value (AdjustInput::drag), to fine-tune from there.
    const double after =
        std::clamp(from + static_cast<double>(dx) / m.width * (high - low), low, high);
    append_steps(events, view, to - after, "Right", "Left");
    return events;
}

Autopilot Autopilot::from_seed(uint64_t seed, double speed,
                               const ObserverModel& observer) {
    Autopilot a;
    a.rng_.seed(seed);
    a.speed_ = speed > 0 ? speed : 1.0;
    a.observer_ = observer;
    return a;
}

Autopilot Autopilot::from_file(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open autopilot script");
    Autopilot a;
    a.scripted_ = true;
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
        line = line.substr(0, line.find('#'));
        std::istringstream words(line);
        double delay;
        std::string key;
        if (!(words >> delay)) continue;  // blank or comment
        if (!(words >> key) || !kKeys.count(key) || delay < 0 || !std::isfinite(delay))
            throw std::runtime_error(
                path + ":" + std::to_string(n) +
                ": expected 'DELAY_MS KEY' with KEY one of 1-9, Enter, "
                "Escape, Left, Right, Up, Down, Q, R");
        a.script_.emplace_back(delay, key);
    }
    return a;
}

Autopilot Autopilot::from_argument(const std::string& argument, double speed,
                                   const ObserverModel& observer) {
    if (!argument.empty() && std::all_of(argument.begin(), argument.end(), ::isdigit))
        return from_seed(std::stoull(argument), speed, observer);
    return from_file(argument);
}

double Autopilot::delay_ms(double median_ms) {
    // Response times are roughly log-normal; sigma 0.35 gives a realistic spread.
    std::lognormal_distribution<double> d(std::log(median_ms), 0.35);
    return d(rng_) / speed_;
}

void Autopilot::plan_screen(int64_t now_ns, const ScreenView& view) {
    queue_.clear();
    double t = 0;
    auto press = [&](double after_ms, const std::string& key) {
        t += after_ms;
        queue_.push_back({now_ns + static_cast<int64_t>(t * 1e6), key});
    };
    switch (view.kind) {
        case ScreenView::Kind::Blank:
            break;
        case ScreenView::Kind::Text:
            press(delay_ms(1500), "Enter");
            break;
        case ScreenView::Kind::Pause:
            press(delay_ms(800), "Enter");
            break;
        case ScreenView::Kind::Choice: {
            // Look, pick a side with an arrow, confirm.
            const int choice = simulated_choice(observer_, view.choice, rng_);
            press(delay_ms(900), choice == 1 ? "Left" : "Right");
            press(delay_ms(250), "Enter");
            break;
        }
        case ScreenView::Kind::Adjust: {
            // Look, then turn the knob to where the match looks like the target, and
            // confirm. Without a target value (a picture) the start is kept.
            const AdjustView& a = view.adjust;
            const double goal =
                a.target ? simulated_match(match_, *a.target, a.lo, a.hi, rng_) : a.value;
            const std::vector<std::string> events =
                adjust_by_ == AdjustBy::wheel  ? adjust_wheel(a, goal)
                : adjust_by_ == AdjustBy::drag ? adjust_drag(a, goal)
                                               : adjust_keys(a, goal);
            double after = 1200;
            for (const std::string& event : events) {
                // Pointer events at least two 60 Hz frames apart, as a hand's are.
                press(is_pointer_event(event) ? std::max(delay_ms(after), 35.0)
                                              : delay_ms(after),
                      event);
                after = 120;
            }
            press(delay_ms(600), "Enter");
            break;
        }
        case ScreenView::Kind::Staircase: {
            const StaircaseView& st = view.staircase;
            const int n = std::max(2, st.answers);
            const bool correct = simulated_detection(detection_, st.delta, 1.0 / n, rng_);
            int answer = st.comparison_place;
            if (!correct) {  // one of the other places, each equally likely
                std::uniform_int_distribution<int> other(1, n - 1);
                answer = other(rng_);
                if (answer >= st.comparison_place) ++answer;
            }
            if (n == 2)
                press(delay_ms(900), answer == 1 ? "Left" : "Right");
            else
                press(delay_ms(900), std::to_string(answer));
            press(delay_ms(250), "Enter");
            break;
        }
        case ScreenView::Kind::Rating: {
            std::bernoulli_distribution change_mind(0.15);
            for (size_t q = 0; q < view.points.size(); ++q) {
                const int points =
                    std::max(1, view.points[q]);  // this question's own scale
                std::uniform_int_distribution<int> point(1, points);
                const int rating = view.is_catch ? view.expected : point(rng_);
                if (change_mind(rng_) &&
                    !view.is_catch) {  // first pick, then a correction
                    press(delay_ms(q == 0 ? 1200 : 700),
                          std::to_string(rating % points + 1));
                    press(delay_ms(350), std::to_string(rating));
                } else {
                    press(delay_ms(q == 0 ? 1200 : 700), std::to_string(rating));
                }
                press(delay_ms(250), "Enter");  // next statement; after the last: confirm
            }
            break;
        }
    }
}

std::vector<std::string> Autopilot::due(int64_t now_ns, const ScreenView& view) {
    std::vector<std::string> keys;
    if (scripted_) return keys;  // scripts are played by the X server (XKeyboard::play)
    if (view.serial != planned_serial_) {
        planned_serial_ = view.serial;
        plan_screen(now_ns, view);
        last_event_ns_ = now_ns;
    } else if (queue_.empty() && view.kind != ScreenView::Kind::Blank &&
               now_ns - last_event_ns_ > kPatienceNs) {
        plan_screen(now_ns, view);
        last_event_ns_ = now_ns;
        ++presses_again_;
    }
    ++frames_since_pointer_;
    while (!queue_.empty() && queue_.front().at_ns <= now_ns) {
        // The runner gets a pointer event from ImGui while drawing the next frame,
        // after that frame's keys: a pointer event waits one frame after the last, a
        // key two, so they reach the flow in the order sent.
        const bool pointer = is_pointer_event(queue_.front().key);
        if (frames_since_pointer_ < (pointer ? 1 : 2)) break;
        if (pointer) frames_since_pointer_ = 0;
        keys.push_back(queue_.front().key);
        last_event_ns_ = now_ns;
        queue_.erase(queue_.begin());
    }
    return keys;
}

}  // namespace lucent::study
