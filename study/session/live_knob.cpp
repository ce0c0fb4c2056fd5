#include "study/session/live_knob.h"

#include <epoxy/gl.h>

#include <algorithm>

#include "renderer/core/common_knobs.h"
#include "renderer/core/display_transform.h"
#include "renderer/core/frame_plan.h"
#include "renderer/gl/errors.h"
#include "renderer/gl/upload.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"

namespace lucent::study {

CpuImage encode_stimulus(const Image& image) {
    CpuImage out{image.width, image.height,
                 std::vector<uint8_t>(size_t(image.width) * image.height * 4)};
    for (size_t i = 0; i < size_t(image.width) * image.height; ++i) {
        for (int c = 0; c < 3; ++c)  // as write_image encodes PNG stimuli
            out.rgba[i * 4 + c] = display_code(image.rgba[i * 4 + c]);
        out.rgba[i * 4 + 3] = 255;  // opaque, like the RGB PNG of the same stimulus
    }
    return out;
}

LiveKnobRenderer::LiveKnobRenderer(std::string what, const Scene& scene, std::string knob,
                                   int width, int height, bool reuse)
    : what_(std::move(what)),
      scene_(scene),
      knob_(std::move(knob)),
      executor_(std::make_unique<gl::FrameExecutor>()) {
    fit_scene_camera(scene_, width, height);
    const std::vector<Knob> knobs = knobs_for(find_technique(scene_.technique));
    const Knob* k = find_knob(knobs, knob_);
    if (!k || !scene_.values.contains(knob_))
        throw StimulusError(what_ + ": technique '" + scene_.technique +
                            "' has no knob '" + knob_ + "'");
    scene_knob_ = find_knob(scene_knobs(), knob_) != nullptr;
    executor_->set_reuse_unchanged_passes(reuse);
}

Scene LiveKnobRenderer::scene_at(double value) const {
    const Technique& technique = find_technique(scene_.technique);
    const std::vector<Knob> knobs = knobs_for(technique);
    const Knob* k = find_knob(knobs, knob_);
    KnobValue v = k->kind == KnobKind::integer ? KnobValue(static_cast<int>(value))
                                               : KnobValue(value);
    try {
        validate_knob_value(*k, v);
    } catch (const std::exception& e) {
        throw StimulusError(what_ + ": " + e.what());
    }
    Scene scene = scene_;
    scene.values.set(knob_, v);
    if (scene_knob_) {  // the light, camera or background follow the values
        Scene rebuilt =
            make_scene(scene.mesh, technique, scene.values, scene.width, scene.height);
        scene.light = rebuilt.light;
        scene.camera = rebuilt.camera;
        scene.background = rebuilt.background;
    }
    return scene;
}

Image LiveKnobRenderer::render_image(double value, bool time_passes) {
    const Scene scene = scene_at(value);
    Image image;
    try {
        const FramePlan plan = make_frame_plan(scene, find_technique(scene.technique));
        executor_->execute(scene, plan, time_passes);
        image = executor_->read_output(plan);
    } catch (const StimulusError&) {
        throw;
    } catch (const std::exception& e) {
        throw StimulusError(what_ + ": " + e.what());
    }
    // NaN or Inf is a renderer or driver bug: participants never see a repaired picture.
    if (const std::size_t bad = count_non_finite_pixels(image); bad > 0)
        throw StimulusError(what_ + " at " + knob_ + " = " + format_knob_value(value) +
                            ": " + std::to_string(bad) +
                            " pixels had NaN or Inf values (a renderer or driver bug); "
                            "refusing to show a repaired picture");
    return image;
}

const StimulusTexture& LiveKnobRenderer::render(double value, bool time_passes) {
    const CpuImage picture = encode_stimulus(render_image(value, time_passes));
    if (texture_.texture.id() && texture_.width == picture.width &&
        texture_.height == picture.height) {
        try {
            glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
            glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
            glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
            glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
            gl::upload_texture_rgba8(texture_.texture, picture.width, picture.height,
                                     picture.rgba);
            gl::check_errors(what_ + ": refilling its picture");
        } catch (const gl::GlError& e) {
            throw StimulusError(e.what());
        }
        return texture_;
    }
    texture_ = upload_texture(picture, what_);
    return texture_;
}

}  // namespace lucent::study
