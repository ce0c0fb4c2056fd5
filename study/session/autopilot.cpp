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

}  // namespace

std::vector<std::string> adjust_keys(const AdjustView& view, double goal) {
    auto on_scale = [&](double v) {
        v = std::clamp(v, view.lo, view.hi);
        return view.log_scale ? std::log10(v) : v;
    };
    std::vector<std::string> keys;
    if (!std::isfinite(goal) || !(view.step > 0) || !(view.fine_step > 0)) return keys;
    const double distance = on_scale(goal) - on_scale(view.value);
    const char* up = distance >= 0 ? "Right" : "Left";
    const double coarse = std::floor(std::abs(distance) / view.step);
    const double fine =
        std::round((std::abs(distance) - coarse * view.step) / view.fine_step);
    for (int i = 0; i < coarse && keys.size() < 1000; ++i) keys.push_back(up);
    for (int i = 0; i < fine && keys.size() < 1000; ++i)
        keys.push_back(std::string("Shift+") + up);
    return keys;
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
            double after = 1200;
            for (const std::string& key : adjust_keys(a, goal)) {
                press(delay_ms(after), key);
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
    }
    while (!queue_.empty() && queue_.front().at_ns <= now_ns) {
        keys.push_back(queue_.front().key);
        queue_.erase(queue_.begin());
    }
    return keys;
}

}  // namespace lucent::study
