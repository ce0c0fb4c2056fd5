#include "study/session/live_stimuli.h"

#include <algorithm>

#include "renderer/core/image.h"
#include "renderer/gl/frame_executor.h"
#include "renderer/render.h"
#include "study/session/live_knob.h"

namespace lucent::study {

const std::vector<ResolvedProtocolStimulus>& LiveOrPrerenderedStimuli::resolved(
    const Protocol& protocol) const {
    if (resolved_for_ != protocol.text) {
        resolved_ = resolve_protocol_stimuli(protocol, images_.images_dir());
        resolved_for_ = protocol.text;
    }
    return resolved_;
}

void LiveOrPrerenderedStimuli::check(const Protocol& protocol) const {
    resolved(protocol);
    Protocol images_only = protocol;  // image stimuli: their files must exist
    std::erase_if(images_only.stimuli, [](const Stimulus& s) { return s.image.empty(); });
    images_.check(images_only);
}

std::vector<StimulusProvenance> LiveOrPrerenderedStimuli::provenance(
    const Protocol& protocol) const {
    std::vector<StimulusProvenance> rows;
    for (const ResolvedProtocolStimulus& r : resolved(protocol))
        rows.push_back(r.provenance);
    return rows;
}

std::shared_ptr<const Scene> LiveOrPrerenderedStimuli::live_scene(
    const Stimulus& spec) const {
    if (!images_.path_for(spec).empty()) return nullptr;
    for (const ResolvedProtocolStimulus& r : resolved_)
        if (r.provenance.stimulus == spec.id) return r.scene;
    return nullptr;
}

StimulusTexture LiveOrPrerenderedStimuli::render(const Stimulus& spec, int width,
                                                 int height) {
    if (!images_.path_for(spec).empty()) return images_.render(spec, width, height);
    const auto resolved_scene = std::find_if(
        resolved_.begin(), resolved_.end(),
        [&](const auto& r) { return r.provenance.stimulus == spec.id && r.scene; });
    if (resolved_scene == resolved_.end())
        throw StimulusError(
            "stimulus '" + spec.id +
            "': not resolved before rendering (check() the protocol first)");
    RenderedImage rendered;
    try {
        // The resolved scene at the window's size: same mesh, density and values, the
        // camera refitted.
        Scene scene = *resolved_scene->scene;
        fit_scene_camera(scene, width, height);
        if (on_render) on_render(scene);
        // One executor per stimulus: its GL objects are gone before the window closes.
        gl::FrameExecutor executor;
        rendered = render_image_counted(executor, scene);
    } catch (const std::exception& e) {
        throw StimulusError("stimulus '" + spec.id + "': " + e.what());
    }
    // NaN or Inf is a renderer or driver bug: participants never see a repaired picture.
    if (rendered.non_finite_pixels > 0)
        throw StimulusError("stimulus '" + spec.id +
                            "': " + std::to_string(rendered.non_finite_pixels) +
                            " pixels had NaN or Inf values (a renderer or driver bug); "
                            "refusing to show a repaired picture");
    return upload_texture(encode_stimulus(rendered.image), "stimulus '" + spec.id + "'");
}

}  // namespace lucent::study
