#include "renderer/techniques/deferred_surface.h"

#include <algorithm>

#include "renderer/techniques/ambient_occlusion_pass.h"

namespace lucent {

void shade_deferred(PlanBuilder& plan, Pass& lighting, const std::vector<Uniform>& camera,
                    bool eye_normal, bool ambient_occlusion) {
    plan.create("surface_position", ResourceFormat::rgba32f);
    plan.create("surface_normal", ResourceFormat::rgba32f);
    plan.create("surface_normal_eye", ResourceFormat::rgba32f);
    Pass surface{"surface",
                 std::string("nearest surface, once: object position, normal") +
                     (ambient_occlusion ? ", AO" : "") +
                     (eye_normal ? ", eye normal" : ""),
                 PassKind::draw_mesh,
                 {"techniques/shaders/mesh.vert", "techniques/shaders/surface.frag", {}}};
    surface.writes = {"surface_position", "surface_normal"};
    if (ambient_occlusion) {
        surface.shader.defines.push_back("WITH_AMBIENT");
        surface.reads.push_back({kAmbientOcclusionStream, ""});
    }
    if (eye_normal) {
        surface.shader.defines.push_back("WITH_EYE_NORMAL");
        surface.writes.push_back("surface_normal_eye");
    }
    surface.writes.push_back("shade_depth");
    surface.uniforms = camera;
    plan.add(surface);

    lighting.kind = PassKind::fullscreen;
    lighting.purpose += ", once per covered pixel";
    lighting.shader.vertex = "gl/shaders/fullscreen.vert";
    lighting.shader.defines.push_back("DEFERRED");
    if (eye_normal) lighting.shader.defines.push_back("WITH_EYE_NORMAL");
    std::erase_if(lighting.reads,
                  [](const Read& r) { return r.resource == kAmbientOcclusionStream; });
    lighting.reads.push_back({"surface_position", ""});
    lighting.reads.push_back({"surface_normal", ""});
    if (eye_normal) lighting.reads.push_back({"surface_normal_eye", ""});
    std::erase_if(lighting.uniforms, [&](const Uniform& u) {
        return std::any_of(camera.begin(), camera.end(),
                           [&](const Uniform& c) { return c.name == u.name; });
    });
    lighting.writes = {"colour"};
}

}  // namespace lucent
