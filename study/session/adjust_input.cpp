#include "study/session/adjust_input.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lucent::study {

AdjustInput::AdjustInput(const Block& block, double start, int64_t onset_ns)
    : log_(block.scale == "log"), onset_ns_(onset_ns) {
    if (block.task != Task::adjust)
        throw std::invalid_argument("block '" + block.id + "' is not an adjust block");
    low_ = log_ ? std::log10(block.range_min) : block.range_min;
    high_ = log_ ? std::log10(block.range_max) : block.range_max;
    min_value_ = block.range_min;
    max_value_ = block.range_max;
    coarse_ = block.step;
    fine_ = block.fine_step;
    start_ = std::clamp(start, block.range_min, block.range_max);
    value_ = start_;
    position_ = std::clamp(log_ ? std::log10(start_) : start_, low_, high_);
}

AdjustInput::AdjustInput(const Block& block, double start, int64_t onset_ns,
                         std::vector<double> series)
    : AdjustInput(block, start, onset_ns) {
    if (series.size() < 2)
        throw std::invalid_argument("block '" + block.id +
                                    "': a series needs at least two values");
    series_ = std::move(series);
    index_ = series_index_at(position_);
    // The page computes the same position from the index (web_series.h).
    position_ = low_ + (high_ - low_) * static_cast<double>(index_) /
                           static_cast<double>(series_.size() - 1);
    start_ = value_ = series_[index_];
}

size_t AdjustInput::series_index_at(double position) const {
    const double last = static_cast<double>(series_.size() - 1);
    const double at = std::round((position - low_) / (high_ - low_) * last);
    return static_cast<size_t>(std::clamp(at, 0.0, last));
}

void AdjustInput::step(bool up, bool fine, int64_t t_ns) {
    const double by = fine ? fine_ : coarse_;
    move_to(position_ + (up ? by : -by), t_ns, fine ? "fine_key" : "key");
}

void AdjustInput::wheel(double notches, int64_t t_ns) {
    if (!std::isfinite(notches)) return;
    move_to(position_ + notches * coarse_, t_ns, "wheel");
}

void AdjustInput::drag(double dx_px, double width_px, int64_t t_ns) {
    if (!std::isfinite(dx_px) || !(width_px > 0) || !std::isfinite(width_px)) return;
    move_to(position_ + dx_px / width_px * (high_ - low_), t_ns, "drag");
}

void AdjustInput::confirm(int64_t t_ns) {
    if (confirmed_) return;
    confirmed_ = true;
    confirm_ns_ = t_ns;
}

void AdjustInput::move_to(double position, int64_t t_ns, const char* input) {
    if (confirmed_) return;
    // Changes are kept in order: keys carry their X event times, the wheel and a drag
    // the frame's, so a key read late may be stamped before the change drawn before it.
    t_ns = std::max(t_ns, adjustments_.empty() ? onset_ns_ : adjustments_.back().t_ns);
    position = std::clamp(position, low_, high_);
    // At an end of the range a further step changes nothing and is not a change.
    if (position == position_) return;
    position_ = position;
    if (!series_.empty()) {
        const size_t index = series_index_at(position);
        if (index == index_) return;
        index_ = index;
        value_ = series_[index];
        adjustments_.push_back({value_, t_ns, input});
        return;
    }
    // The ends exactly, whatever log10 and pow round to.
    value_ = position == low_    ? min_value_
             : position == high_ ? max_value_
             : log_ ? std::clamp(std::pow(10.0, position), min_value_, max_value_)
                    : position;
    adjustments_.push_back({value_, t_ns, input});
}

TrialOutcome AdjustInput::outcome(const std::string& question_id) const {
    const int64_t onset_ns = onset_ns_;
    if (!confirmed_) throw std::logic_error("AdjustInput::outcome before confirm()");
    TrialOutcome out;
    out.onset_ns = onset_ns;
    out.confirm_ns = confirm_ns_;
    Response r;
    r.question = question_id;
    r.rating = 1;
    r.rt_ms = std::max<int64_t>(0, confirm_ns_ - onset_ns) / 1e6;
    r.changes = static_cast<int>(adjustments_.size());
    r.first_choice_ns = adjustments_.empty() ? confirm_ns_ : adjustments_.front().t_ns;
    r.final_choice_ns = adjustments_.empty() ? confirm_ns_ : adjustments_.back().t_ns;
    out.responses.push_back(r);
    out.final_value = value_;
    out.adjustments = adjustments_;
    return out;
}

}  // namespace lucent::study
