#pragma once
// The adjust screen's input rules (issue 31), GL-free so they are unit-tested: the
// participant turns one knob of the match object with the arrows (a coarse step), Shift +
// arrows (a fine step), the mouse wheel (a coarse step per notch) or a drag across the
// match (its width spans the whole range), and confirms with Enter. Steps are taken on
// the block's scale, the knob's value or its log10, and held inside the block's range.
// Every change is kept with its time and input, as the store records it.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/store_types.h"

namespace lucent::study {

class AdjustInput {
public:
    // `block`: an adjust block (its range, steps and scale); `start`: the trial's
    // planned start value (clamped into the range). Throws std::invalid_argument when the
    // block is not an adjust block.
    AdjustInput(const Block& block, double start, int64_t onset_ns);
    // In the browser: the knob moves as above, and its value is the nearest of the
    // `series` values (adjust_series_values(block): the pre-rendered pictures); the start
    // is the series value nearest `start`, and only a move to another value is a change.
    AdjustInput(const Block& block, double start, int64_t onset_ns,
                std::vector<double> series);

    // One step up (Right/Up) or down (Left/Down); `fine` with Shift.
    void step(bool up, bool fine, int64_t t_ns);
    // Wheel notches (positive: up); fractional notches (touchpads) move proportionally.
    void wheel(double notches, int64_t t_ns);
    // A drag of `dx_px` pixels across a match `width_px` wide: the whole width spans
    // the range on the scale.
    void drag(double dx_px, double width_px, int64_t t_ns);
    void confirm(int64_t t_ns);

    double value() const { return value_; }
    double start() const { return start_; }
    bool confirmed() const { return confirmed_; }
    bool at_min() const { return position_ <= low_; }
    bool at_max() const { return position_ >= high_; }
    // The index of the value in the series (0 without one).
    size_t series_index() const { return index_; }
    // Increases with every change of the value: the renderer redraws the match only
    // when it moved.
    int revision() const { return static_cast<int>(adjustments_.size()); }
    const std::vector<Adjustment>& adjustments() const { return adjustments_; }
    // The trial's answer (requires confirmed()): the block's question with rating 1
    // ("confirmed"), rt from the onset to the confirmation, the changes counted, the
    // first and last change's times (the confirmation's when nothing changed); and the
    // confirmed value with every change.
    TrialOutcome outcome(const std::string& question_id) const;

private:
    void move_to(double position, int64_t t_ns, const char* input);
    size_t series_index_at(double position) const;  // nearest series value's index

    bool log_ = false;
    double low_ = 0, high_ = 0;             // the range on the scale
    double min_value_ = 0, max_value_ = 0;  // and as values (its ends exactly)
    double coarse_ = 0, fine_ = 0;
    double position_ = 0;  // the value on the scale
    double value_ = 0, start_ = 0;
    int64_t onset_ns_ = 0;
    bool confirmed_ = false;
    int64_t confirm_ns_ = 0;
    std::vector<Adjustment> adjustments_;
    std::vector<double> series_;  // empty in the lab
    size_t index_ = 0;
};

}  // namespace lucent::study
