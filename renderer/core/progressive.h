#pragma once
// Progressive refinement for interactive views (the explorer) of a technique whose image
// is a mean over N stratified samples: frames of a few samples each, every frame with
// the stratification seed advanced, averaged with weights equal to their sample counts
// until the set's N is reached. The mean estimates the same integral as one frame at N
// (unbiased, with the golden-ratio seed offsets interleaving the strata), so a view stays
// interactive however large N is and converges when nothing changes. GL-free.
#include <optional>
#include <string>

#include "renderer/core/image.h"
#include "renderer/core/knobs.h"

namespace lucent {

// Declared by a technique (Technique::progressive_refinement()); empty samples_knob:
// the technique is not refined progressively.
struct ProgressiveRefinement {
    std::string samples_knob;  // integer knob: N, the target
    std::string seed_knob;     // integer knob: offsets the stratification
    int per_frame = 0;         // samples per interactive frame
    bool enabled() const { return !samples_knob.empty() && per_frame > 0; }
};

class ProgressiveAccumulator {
public:
    explicit ProgressiveAccumulator(ProgressiveRefinement refinement)
        : refinement_(std::move(refinement)) {}

    // The values to render next for a set whose values are `values` (their samples knob
    // is the target N) seen through `view` (whatever else must match between frames:
    // camera, size, mesh). A change of either restarts the mean (but a larger N, which
    // goes on from the mean so far). nullopt: the mean has
    // reached N, nothing needs rendering. Seeds wrap inside the seed knob's range
    // [0, seed_limit].
    std::optional<KnobValues> next(const KnobValues& values, const std::string& view,
                                   int seed_limit);
    // Adds the frame rendered with the values the last next() returned.
    void add(const Image& frame);

    const Image& mean() const { return mean_; }
    int samples() const { return samples_; }  // summed over the frames added
    int target() const { return target_; }
    int frames() const { return frames_; }
    bool converged() const { return frames_ > 0 && samples_ >= target_; }

private:
    ProgressiveRefinement refinement_;
    std::string key_;  // the values (but the samples and seed) and the view
    int target_ = 0, samples_ = 0, frames_ = 0, pending_samples_ = 0;
    Image mean_;
};

}  // namespace lucent
