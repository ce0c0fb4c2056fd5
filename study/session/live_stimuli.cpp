#include "study/session/live_stimuli.h"

#include <cmath>

#include "renderer/core/image.h"
#include "renderer/gl/frame_executor.h"
#include "renderer/render.h"

namespace lucent::study {
namespace {

RenderRequest request_for(const StimulusSpec& spec, int width, int height) {
    RenderRequest r;
    if (!spec.mesh.empty()) r.mesh = spec.mesh;
    r.technique = spec.technique;
    for (const auto& [name, value] : spec.parameters)
        r.settings.push_back(parse_assignment(name + "=" + value));
    r.width = width;
    r.height = height;
    return r;
}

}  // namespace

void LiveOrPrerenderedStimuli::check(const Protocol& protocol) const {
    for (const StimulusSpec& s : protocol.stimuli) {
        if (!images_.path_for(s).empty() || !s.image.empty()) continue;
        try {
            build_scene(
                request_for(s, protocol.stimulus_width, protocol.stimulus_height));
        } catch (const std::exception& e) {
            throw StimulusError(protocol.source + ": stimulus '" + s.id +
                                "': " + e.what());
        }
    }
    Protocol images_only = protocol;  // image stimuli: their files must exist
    std::erase_if(images_only.stimuli,
                  [](const StimulusSpec& s) { return s.image.empty(); });
    images_.check(images_only);
}

StimulusTexture LiveOrPrerenderedStimuli::render(const StimulusSpec& spec, int width,
                                                 int height) {
    if (!images_.path_for(spec).empty()) return images_.render(spec, width, height);
    RenderedImage rendered;
    try {
        // One executor per stimulus: its GL objects are gone before the window closes.
        gl::FrameExecutor executor;
        rendered =
            render_image_counted(executor, build_scene(request_for(spec, width, height)));
    } catch (const std::exception& e) {
        throw StimulusError("stimulus '" + spec.id + "': " + e.what());
    }
    // NaN or Inf is a renderer or driver bug: participants never see a repaired picture.
    if (rendered.non_finite_pixels > 0)
        throw StimulusError("stimulus '" + spec.id +
                            "': " + std::to_string(rendered.non_finite_pixels) +
                            " pixels had NaN or Inf values (a renderer or driver bug); "
                            "refusing to show a repaired picture");
    const Image& image = rendered.image;
    CpuImage out{image.width, image.height,
                 std::vector<uint8_t>(size_t(image.width) * image.height * 4)};
    for (size_t i = 0; i < size_t(image.width) * image.height; ++i) {
        for (int c = 0; c < 3; ++c)  // as write_image encodes PNG stimuli
            out.rgba[i * 4 + c] = static_cast<uint8_t>(
                std::lround(srgb_encode(image.rgba[i * 4 + c]) * 255.f));
        out.rgba[i * 4 + 3] = 255;  // opaque, like the RGB PNG of the same stimulus
    }
    return upload_texture(out, "stimulus '" + spec.id + "'");
}

}  // namespace lucent::study
