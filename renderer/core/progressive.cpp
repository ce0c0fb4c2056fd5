#include "renderer/core/progressive.h"

#include <algorithm>
#include <stdexcept>

namespace lucent {
namespace {

// Every value but the two the refinement varies, and the view.
std::string refinement_key(const KnobValues& values, const ProgressiveRefinement& r,
                           const std::string& view) {
    std::string key = view;
    for (const auto& [name, value] : values.all())
        if (name != r.samples_knob && name != r.seed_knob)
            key += "\n" + name + "=" + format_knob_value(value);
    return key;
}

}  // namespace

std::optional<KnobValues> ProgressiveAccumulator::next(const KnobValues& values,
                                                       const std::string& view,
                                                       int seed_limit) {
    const int target = std::max(1, values.integer(refinement_.samples_knob));
    std::string key = refinement_key(values, refinement_, view);
    // A larger N with nothing else changed goes on from the mean so far.
    if (key != key_ || target < samples_) {
        key_ = std::move(key);
        samples_ = frames_ = 0;
        mean_ = Image();
    }
    target_ = target;
    if (converged()) return std::nullopt;
    KnobValues frame = values;
    pending_samples_ = std::min(refinement_.per_frame, target_ - samples_);
    frame.set(refinement_.samples_knob, pending_samples_);
    // Frame k uses seed + k: the technique's offsets frac(0.5 + seed 0.618..) are then a
    // Kronecker sequence, which fills the strata evenly.
    const long long seed = values.integer(refinement_.seed_knob) + frames_;
    frame.set(refinement_.seed_knob,
              static_cast<int>(seed % (static_cast<long long>(seed_limit) + 1)));
    return frame;
}

void ProgressiveAccumulator::add(const Image& frame) {
    if (pending_samples_ <= 0)
        throw std::logic_error("ProgressiveAccumulator::add without next()");
    if (frames_ == 0) {
        mean_ = frame;
    } else {
        if (frame.width != mean_.width || frame.height != mean_.height)
            throw std::logic_error("ProgressiveAccumulator::add: frame size changed");
        // Running mean weighted by sample counts: mean += (frame - mean) w / (n + w).
        const float weight = static_cast<float>(pending_samples_) /
                             static_cast<float>(samples_ + pending_samples_);
        for (std::size_t i = 0; i < mean_.rgba.size(); ++i)
            mean_.rgba[i] += (frame.rgba[i] - mean_.rgba[i]) * weight;
    }
    samples_ += pending_samples_;
    pending_samples_ = 0;
    ++frames_;
}

}  // namespace lucent
