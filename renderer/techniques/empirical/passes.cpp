// What the empirical technique adds to a frame plan (thesis ch. 3, apps. B-C):
//   ambient_occlusion  per-vertex AO bake            -> vertex_ao        (ka*Ia != 0)
//   front_depth        nearest surface depth         -> front_depth      (wb != 0)
//                      (deferred: and its surface)   -> front_surface
//   second_layer       depth peeling (App. B)        -> second_depth     (wb != 0)
//   smooth_back_layer  depth-aware 5x5 / 3x3 blur    -> smoothed_depth   (wb != 0, kernel
//   > 1) shade              Eq. 3.6                       -> colour
// Terms that cannot change the image select a shader variant without them, and the
// passes that only fed them are culled by PlanBuilder::compile().
#include <glm/gtc/matrix_inverse.hpp>

#include "techniques/empirical/empirical.h"

namespace lucent::empirical {

ResourceFormat depth_format(const std::string& depth_precision) {
    if (depth_precision == "16") return ResourceFormat::depth16;
    if (depth_precision == "24") return ResourceFormat::depth24;
    return ResourceFormat::depth32f;
}

double peel_epsilon(const std::string& depth_precision) {
    return depth_precision == "16" ? 1.0 / 65535.0 : 1e-6;
}

namespace {

std::vector<Uniform> camera_uniforms(const Scene& scene) {
    const glm::mat4 view = scene.camera.view();
    return {{"u_model_view", view},
            {"u_projection", scene.camera.projection()},
            {"u_normal_matrix", glm::inverseTranspose(glm::mat3(view))}};
}

std::vector<Uniform> with(std::vector<Uniform> a, const std::vector<Uniform>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan, Shading shading) {
    const Params p = params(scene);
    const glm::vec3 light_ambient = scene.light.ambient;
    // Which terms of Eq. 3.6 can change the image (all of them in full mode).
    const bool ambient_term =
        plan.full() || (p.ambient != 0.0 && light_ambient != glm::vec3(0.0f));
    const bool backlight_term = plan.full() || p.backlight != 0.0;
    const bool smoothing = backlight_term && (plan.full() || p.blur_kernel > 1);
    // With the backlight the front layer is rasterised anyway (the peel reads it): it
    // then also stores the surface, and `shade` lights it once per pixel instead of
    // rasterising the mesh a third time and shading hidden fragments. The same floats
    // in, the same colour out (tested bit for bit against Shading::forward); only with
    // 32f depth, whose texels are the fragments' exact depths (at 16 or 24 bits the
    // front layer's visibility would be resolved coarser than the shading's).
    const bool deferred = backlight_term && shading == Shading::deferred_when_exact &&
                          p.depth_precision == "32f";
    const ResourceFormat depth = depth_format(p.depth_precision);
    const auto camera = camera_uniforms(scene);
    const std::string mesh_vert = "techniques/empirical/shaders/mesh.vert";

    plan.create("vertex_ao", ResourceFormat::vertex_float);
    plan.create("front_depth", depth);
    plan.create("second_depth", depth);
    plan.create("smoothed_depth", ResourceFormat::r32f);
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);

    // Step 0 (Sec. 3.1, Eq. 3.5): per-vertex AO; culled unless the ambient term reads it.
    Pass ao{"ambient_occlusion", "bake (or load cached) per-vertex AO, Eq. 3.5",
            PassKind::bake_ambient_occlusion};
    ao.writes = {"vertex_ao"};
    ao.ao_rays = p.ao_rays;
    plan.add(ao);

    // Step 1 (Sec. 3.1): depth of the nearest surface, read by the peel (and, deferred,
    // the surface that `shade` lights).
    Pass front{"front_depth",
               "depth of the first layer",
               PassKind::draw_mesh,
               {mesh_vert, "techniques/empirical/shaders/depth_only.frag", {}}};
    front.writes = {"front_depth"};
    front.uniforms = camera;
    if (deferred) {
        plan.create("front_surface", ResourceFormat::rgba32f);
        front.purpose = "depth, interpolated normal and AO of the first layer";
        front.shader.fragment = "techniques/empirical/shaders/front_surface.frag";
        front.writes = {"front_surface", "front_depth"};
        if (ambient_term) {
            front.shader.defines.push_back("WITH_AMBIENT_OCCLUSION");
            front.reads.push_back({"vertex_ao", ""});
        }
    }
    plan.add(front);

    std::string back_layer;
    if (backlight_term) {
        // Step 2 (App. B): the second layer by depth peeling.
        Pass peel{"second_layer",
                  "depth peeling: nearest depth behind front + epsilon",
                  PassKind::draw_mesh,
                  {mesh_vert, "techniques/empirical/shaders/peel.frag", {}}};
        peel.reads = {{"front_depth", ""}};
        peel.writes = {"second_depth"};
        peel.uniforms = with(
            camera, {{"u_epsilon", static_cast<float>(peel_epsilon(p.depth_precision))}});
        plan.add(peel);
        back_layer = "second_depth";

        if (smoothing) {
            // Step 3 (App. C.2.2): depth-aware smoothing of the back layer. In full mode
            // with blur_kernel = 1 this runs a 1x1 kernel, an exact copy.
            const int size = p.blur_kernel;
            Pass smooth{"smooth_back_layer",
                        "depth-aware " + std::to_string(size) + "x" +
                            std::to_string(size) +
                            " smoothing of the second layer (Eq. C.1)",
                        PassKind::fullscreen,
                        {"gl/shaders/fullscreen.vert",
                         "techniques/empirical/shaders/smooth_depth.frag",
                         {"KERNEL_SIZE " + std::to_string(size)}}};
            smooth.reads = {{"second_depth", "back_depth"}};
            smooth.writes = {"smoothed_depth"};
            smooth.uniforms = {{"u_falloff", static_cast<float>(kSmoothingFalloff)}};
            plan.add(smooth);
            back_layer = "smoothed_depth";
        }
    }

    // Step 4 (Eq. 3.6): shading, one variant per set of live terms.
    Pass shade{"shade",
               "Eq. 3.6: ambient*AO + diffuse + specular + backlight(thickness)",
               PassKind::draw_mesh,
               {mesh_vert, "techniques/empirical/shaders/shade.frag", {}}};
    if (deferred) {
        shade.purpose += ", once per pixel of the front layer";
        shade.kind = PassKind::fullscreen;
        shade.shader = {"gl/shaders/fullscreen.vert",
                        "techniques/empirical/shaders/shade.frag",
                        {"DEFERRED"}};
        shade.reads = {{"front_depth", ""}, {"front_surface", ""}};
    }
    std::vector<Uniform> u = {
        {"u_albedo", glm::vec3(p.albedo)},
        {"u_diffuse_contribution", static_cast<float>(p.diffuse_contribution)},
        {"u_specular_contribution", static_cast<float>(p.specular_contribution)},
        {"u_specular", static_cast<float>(p.specular)},
        {"u_shininess", static_cast<float>(p.shininess)},
        {"u_light_diffuse", scene.light.diffuse},
        {"u_light_specular", scene.light.specular},
        {"u_light_direction", scene.light.direction},
    };
    if (ambient_term) {
        shade.shader.defines.push_back("WITH_AMBIENT_OCCLUSION");
        if (!deferred) shade.reads.push_back({"vertex_ao", ""});
        u.push_back({"u_ambient", static_cast<float>(p.ambient)});
        u.push_back({"u_light_ambient", light_ambient});
    }
    if (backlight_term) {
        shade.shader.defines.push_back("WITH_BACKLIGHT");
        shade.reads.push_back({back_layer, "back_depth"});
        u.push_back({"u_backlight", static_cast<float>(p.backlight)});
        u.push_back({"u_thickness_exponent", static_cast<float>(p.thickness_exponent)});
        u.push_back({"u_diffuse_weight", static_cast<float>(p.diffuse_weight)});
        u.push_back({"u_near", scene.camera.near_plane});
        u.push_back({"u_far", scene.camera.far_plane});
        u.push_back({"u_diameter", scene.bounds.diameter()});
    }
    shade.uniforms = deferred ? u : with(camera, u);
    shade.writes = deferred ? std::vector<std::string>{"colour"}
                            : std::vector<std::string>{"colour", "shade_depth"};
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
    plan.set_output("colour");
}

}  // namespace lucent::empirical
