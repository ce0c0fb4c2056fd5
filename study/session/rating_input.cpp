#include "study/session/rating_input.h"

#include <algorithm>

namespace lucent::study {

RatingInput::RatingInput(std::vector<int> points, int64_t onset_ns)
    : state_(points.size()), points_(std::move(points)), onset_ns_(onset_ns) {}

RatingInput RatingInput::forced_choice(int64_t onset_ns, int alternatives) {
    RatingInput input(std::vector<int>{alternatives}, onset_ns);
    input.choice_ = true;
    return input;
}

void RatingInput::set(int question, int value, int64_t t_ns) {
    if (confirmed_ || value < 1 || value > points_[question]) return;
    State& s = state_[question];
    if (!s.rating)
        s.first_ns = t_ns;
    else if (*s.rating != value)
        ++s.changes;
    else
        return;  // the same value again is not a change
    s.rating = value;
    s.final_ns = t_ns;
}

void RatingInput::key(RatingKey key, int digit, int64_t t_ns) {
    if (confirmed_) return;
    const int n = static_cast<int>(state_.size());
    State& s = state_[focus_];
    const int points = points_[focus_];
    switch (key) {
        case RatingKey::Digit:
            set(focus_, digit, t_ns);
            break;
        // The first arrow press picks the middle point: nothing is chosen before a key.
        // A choice of two: the arrows point at the alternative on that side.
        case RatingKey::Left:
            set(focus_,
                choice_ && points == 2 ? 1
                : s.rating             ? std::max(1, *s.rating - 1)
                                       : (points + 1) / 2,
                t_ns);
            break;
        case RatingKey::Right:
            set(focus_,
                choice_ && points == 2 ? 2
                : s.rating             ? std::min(points, *s.rating + 1)
                                       : (points + 1) / 2,
                t_ns);
            break;
        case RatingKey::Up:
            focus_ = std::max(0, focus_ - 1);
            break;
        case RatingKey::Down:
            focus_ = std::min(n - 1, focus_ + 1);
            break;
        case RatingKey::Enter:
            if (!s.rating) break;  // Enter never answers for the participant
            if (all_answered()) {
                confirmed_ = true;
                confirm_ns_ = t_ns;
                break;
            }
            for (int step = 1; step <= n; ++step)  // on to the next unanswered statement
                if (!state_[(focus_ + step) % n].rating) {
                    focus_ = (focus_ + step) % n;
                    break;
                }
            break;
    }
}

void RatingInput::click(int question, int value, int64_t t_ns) {
    if (question < 0 || question >= static_cast<int>(state_.size())) return;
    focus_ = question;
    set(question, value, t_ns);
}

void RatingInput::click_next(int64_t t_ns) {
    if (confirmed_ || !all_answered()) return;
    confirmed_ = true;
    confirm_ns_ = t_ns;
}

bool RatingInput::all_answered() const {
    return std::all_of(state_.begin(), state_.end(),
                       [](const State& s) { return s.rating.has_value(); });
}

std::vector<Response> RatingInput::responses(
    const std::vector<std::string>& question_ids) const {
    std::vector<Response> out;
    for (size_t q = 0; q < state_.size(); ++q) {
        const State& s = state_[q];
        Response r;
        r.question = question_ids[q];
        r.rating = s.rating.value_or(0);
        r.rt_ms = std::max<int64_t>(0, s.final_ns - onset_ns_) / 1e6;
        r.changes = s.changes;
        r.first_choice_ns = s.first_ns;
        r.final_choice_ns = s.final_ns;
        out.push_back(r);
    }
    return out;
}

}  // namespace lucent::study
