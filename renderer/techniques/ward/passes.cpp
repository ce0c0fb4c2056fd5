// What the ward and contrast_reversed techniques add to a frame plan:
//   ambient_occlusion  per-vertex AO bake         -> vertex_ao   (ka*Ia != 0)
//   shade              Eq. 14 or Eq. 15            -> colour
// A zero diffuse weight or zero specular reflectance compiles that term out of the
// shader; no AO term culls the bake.

#include "renderer/techniques/ambient_occlusion_pass.h"
#include "renderer/techniques/ward/ward.h"

namespace lucent::ward {

void add_passes(const Scene& scene, PlanBuilder& plan, Variant variant) {
    const Params p = params(scene, variant);
    const bool ambient_term = plan.full() || has_ambient_term(p, scene.light);
    const bool diffuse_term =
        plan.full() || (p.diffuse != 0.0 && scene.light.diffuse != glm::vec3(0.0f));
    const bool specular_term = plan.full() || has_specular_term(p, scene.light);

    // Per-vertex AO for the ambient term; culled when the shader does not read it.
    add_ambient_occlusion(plan, scene, p.ao_rays,
                          "bake (or load cached) per-vertex AO for the ambient term");
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);

    const glm::mat4 view = scene.camera.view();
    Pass shade{
        "shade",
        variant == Variant::ward ? "Eq. 14: ambient*AO + Ward diffuse + Ward specular"
                                 : "Eq. 15: ambient*AO + reversed diffuse Id*chroma*(1 - "
                                   "Y(Kd)*N.L) + Ward specular",
        PassKind::draw_mesh,
        {"techniques/shaders/mesh.vert", "techniques/ward/shaders/shade.frag", {}}};
    shade.uniforms =
        with_uniforms(mesh_transform_uniforms(view, scene.camera.projection()),
                      {{"u_albedo", glm::vec3(p.albedo)},
                       {"u_light_diffuse", scene.light.diffuse},
                       {"u_light_direction", scene.light.direction}});
    if (ambient_term) {
        shade.shader.defines.push_back("WITH_AMBIENT_OCCLUSION");
        shade.reads.push_back({kAmbientOcclusionStream, ""});
        shade.uniforms.push_back({"u_ambient", static_cast<float>(p.ambient)});
        shade.uniforms.push_back({"u_light_ambient", scene.light.ambient});
    }
    if (diffuse_term) {
        shade.shader.defines.push_back("WITH_DIFFUSE");
        if (variant == Variant::contrast_reversed) {
            shade.shader.defines.push_back("REVERSED_DIFFUSE");
            shade.uniforms.push_back(
                {"u_albedo_chroma", glm::vec3(albedo_chroma(p.albedo))});
            shade.uniforms.push_back(
                {"u_albedo_luminance", static_cast<float>(albedo_luminance(p.albedo))});
        }
        shade.uniforms.push_back({"u_diffuse", static_cast<float>(p.diffuse)});
    }
    if (specular_term) {
        shade.shader.defines.push_back("WITH_SPECULAR");
        shade.uniforms.push_back(
            {"u_specular_reflectance", static_cast<float>(p.specular_reflectance)});
        shade.uniforms.push_back({"u_roughness", static_cast<float>(p.roughness)});
        shade.uniforms.push_back({"u_light_specular", scene.light.specular});
    }
    shade.writes = {"colour", "shade_depth"};
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
    plan.set_output("colour");
}

}  // namespace lucent::ward
