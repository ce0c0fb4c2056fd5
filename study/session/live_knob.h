#pragma once
// A live stimulus drawn with one knob at a chosen value (issue 31): an adjust trial's
// match, a staircase's comparison. It keeps the stimulus's resolved scene and one frame
// executor with pass reuse on, so a new value re-runs only the passes that knob touches
// (the explorer's rule, core/pass_reuse.h), and one texture, refilled in place while the
// size stays. Needs a current GL context for render() and its destruction.
#include <memory>
#include <string>

#include "renderer/core/image.h"
#include "renderer/core/scene.h"
#include "renderer/gl/frame_executor.h"
#include "study/session/stimulus_source.h"

namespace lucent::study {

class LiveKnobRenderer {
public:
    // `scene`: the stimulus's resolved scene (at any size: it is refitted to width x
    // height); `knob`: a scalar knob of its technique or of scene_knobs(); `what` names
    // the stimulus in errors. Throws StimulusError when the technique lacks the knob.
    // `reuse` false runs every pass every frame (`lucent bench adjust`'s baseline).
    LiveKnobRenderer(std::string what, const Scene& scene, std::string knob, int width,
                     int height, bool reuse = true);

    // The scene with the knob at `value` (validated against the knob's range: a value
    // outside it throws StimulusError), light and camera rebuilt when the knob is one of
    // the scene's own.
    Scene scene_at(double value) const;
    // Renders the scene at `value` into the float image (finite, else StimulusError:
    // NaN or Inf pixels are a renderer or driver bug and never shown repaired).
    Image render_image(double value, bool time_passes = false);
    // render_image(), sRGB-encoded as the PNG stimuli, into texture() (reused while the
    // size is the same).
    const StimulusTexture& render(double value, bool time_passes = false);
    const StimulusTexture& texture() const { return texture_; }
    // The last frame's passes, those reused marked cached.
    const gl::FrameTimings& last_timings() const { return executor_->last_timings(); }
    const std::string& knob() const { return knob_; }

private:
    std::string what_;
    Scene scene_;
    std::string knob_;
    bool scene_knob_ = false;  // a light, camera or background knob
    std::unique_ptr<gl::FrameExecutor> executor_;
    StimulusTexture texture_;
};

// The rendered float image as the 8-bit sRGB picture a PNG stimulus holds (opaque).
CpuImage encode_stimulus(const Image& image);

}  // namespace lucent::study
