#pragma once
// Stimuli rendered live by the renderer's techniques (render.h: the same single-image
// path as `lucent render` and the stimulus batch), or taken from a pre-rendered image
// when one exists (an `image` stimulus, or <id>.png|.tif|.exr in the images directory).
#include <string>

#include "study/session/stimulus_source.h"

namespace lucent::study {

class LiveOrPrerenderedStimuli : public StimulusRenderer {
public:
    explicit LiveOrPrerenderedStimuli(std::string images_dir)
        : images_(std::move(images_dir)) {}
    // Pre-rendered file if there is one, else renders technique + parameters at
    // width x height into a texture (GL context current), sRGB-encoded as PNG output.
    StimulusTexture render(const StimulusSpec& spec, int width, int height) override;
    // Without GL: every live stimulus's technique, parameters and mesh are valid.
    void check(const Protocol& protocol) const override;
    std::vector<StimulusProvenance> provenance(const Protocol& protocol) const override {
        return images_.provenance(protocol);
    }

private:
    PrerenderedStimuli images_;
};

}  // namespace lucent::study
