#include "renderer/render.h"

#include <stdexcept>

#include "renderer/core/technique.h"
#include "renderer/techniques/registry.h"

namespace lucent {

Scene build_scene(const RenderRequest& request) {
    if (request.width <= 0 || request.height <= 0 || request.width > 16384 ||
        request.height > 16384)
        throw std::invalid_argument(
            "size: " + std::to_string(request.width) + "x" +
            std::to_string(request.height) +
            " is out of range (accepted: WxH with each in [1, 16384])");
    const Technique& technique = find_technique(request.technique);
    const std::vector<Knob> knobs = knobs_for(technique);
    KnobValues values = resolve_knob_values(knobs, request.settings);
    auto mesh = std::make_shared<const Mesh>(load_mesh(request.mesh));
    Scene scene = make_scene(std::move(mesh), technique, std::move(values), request.width,
                             request.height);
    technique.check_scene(scene);
    return scene;
}

RenderedImage render_image_counted(gl::FrameExecutor& executor, const Scene& scene,
                                   PlanMode mode) {
    const Technique& technique = find_technique(scene.technique);
    const FramePlan plan = make_frame_plan(scene, technique, mode);
    RenderedImage rendered{executor.render(scene, plan), 0};
    rendered.non_finite_pixels = count_non_finite_pixels(rendered.image);
    replace_non_finite(rendered.image);
    return rendered;
}

Image render_image(gl::FrameExecutor& executor, const Scene& scene, PlanMode mode) {
    return render_image_counted(executor, scene, mode).image;
}

}  // namespace lucent
