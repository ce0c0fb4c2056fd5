#pragma once
// Stimuli rendered live by the renderer's techniques (render.h: the same single-image
// path as `lucent render` and the stimulus batch), or taken from a pre-rendered image
// when one exists (an `image` stimulus, or <id>.png|.tif|.exr in the images directory).
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "renderer/core/scene.h"
#include "study/session/stimulus_provenance.h"
#include "study/session/stimulus_source.h"

namespace lucent::study {

class LiveOrPrerenderedStimuli : public StimulusRenderer {
public:
    explicit LiveOrPrerenderedStimuli(std::string images_dir)
        : images_(std::move(images_dir)) {}
    // Pre-rendered file if there is one, else renders the scene resolved for the
    // stimulus (resolve_protocol_stimuli: the scene whose values the database records)
    // at width x height into a texture (GL context current), sRGB-encoded as PNG output.
    StimulusTexture render(const Stimulus& spec, int width, int height) override;
    // Without GL: resolves every stimulus once (technique, parameters, mesh, the
    // technique's own scene checks) and keeps the result for provenance() and render().
    void check(const Protocol& protocol) const override;
    // The rows of the resolution check() made (made now if check() was not called).
    std::vector<StimulusProvenance> provenance(const Protocol& protocol) const override;

    // The resolved scene of a live stimulus rendered live (null for an image stimulus
    // and one shown from an --images file): what a LiveKnobRenderer (live_knob.h) turns
    // a knob of. check() the protocol first.
    std::shared_ptr<const Scene> live_scene(const Stimulus& spec) const;

    // Called with each scene just before it is rendered (tests: the scene the renderer
    // received).
    std::function<void(const Scene&)> on_render;

private:
    // The resolution of `protocol`'s stimuli, made on first use and again only for
    // another protocol (another text), so a station never shows one protocol's scenes
    // for another's stimuli.
    const std::vector<ResolvedProtocolStimulus>& resolved(const Protocol& protocol) const;

    PrerenderedStimuli images_;
    // The one resolution of the protocol's stimuli (each live one with its scene), and
    // the text of the protocol it was made for.
    mutable std::vector<ResolvedProtocolStimulus> resolved_;
    mutable std::optional<std::string> resolved_for_;
};

}  // namespace lucent::study
