// What the empirical technique adds to a frame plan (thesis ch. 3, apps. B-C):
//   ambient_occlusion  per-vertex AO bake            -> vertex_ao        (ka*Ia != 0)
//   front_depth        nearest surface depth         -> front_depth      (wb != 0, peel)
//                      (deferred: and its surface)   -> front_surface
//   second_layer       depth peeling (App. B), or    -> second_depth     (wb != 0)
//                      a closed mesh's back faces
//   smooth_back_layer  depth-aware 5x5 / 3x3 blur    -> smoothed_depth   (wb != 0, k > 1)
//   shade              Eq. 3.6                       -> colour
// Terms that cannot change the image select a shader variant without them, and the
// passes that only fed them are culled by PlanBuilder::compile().

#include "renderer/techniques/ambient_occlusion_pass.h"
#include "renderer/techniques/empirical/empirical.h"

namespace lucent::empirical {

ResourceFormat depth_format(const std::string& depth_precision) {
    if (depth_precision == "16") return ResourceFormat::depth16;
    if (depth_precision == "24") return ResourceFormat::depth24;
    return ResourceFormat::depth32f;
}

double peel_epsilon(const std::string& depth_precision) {
    return depth_precision == "16" ? 1.0 / 65535.0 : 1e-6;
}

namespace {}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan, SurfaceShading shading) {
    const Params p = params(scene);
    const glm::vec3 light_ambient = scene.light.ambient;
    // Which terms of Eq. 3.6 can change the image (all of them in full mode).
    const bool ambient_term =
        plan.full() || (p.ambient != 0.0 && light_ambient != glm::vec3(0.0f));
    const bool backlight_term = plan.full() || p.backlight != 0.0;
    const bool smoothing = backlight_term && (plan.full() || p.blur_kernel > 1);
    const ResourceFormat depth = depth_format(p.depth_precision);
    const auto camera =
        mesh_transform_uniforms(scene.camera.view(), scene.camera.projection());
    // Every mesh pass draws its vertices at bit-identical depths (`invariant`), which the
    // peel's comparison of layers relies on.
    const std::string mesh_vert = "techniques/shaders/mesh.vert";
    const std::string invariant = "INVARIANT_POSITION";
    const ShaderDesc depth_only{
        mesh_vert, "techniques/empirical/shaders/depth_only.frag", {invariant}};
    // A closed mesh facing out, seen from outside: the nearest surface of every pixel is
    // a front face and the one behind it a back face (the first exit). The second layer
    // is then the nearest back face, rasterised with front faces culled and without
    // reading the first layer (no peel), and `shade` rasterises front faces only and
    // smooths the back layer itself. On other meshes, or with layer_method = peel, faces
    // of both orientations count and the second layer is peeled (App. B), as ray hits do.
    const bool by_facing = p.layer_method == "auto" && facing_separates_layers(scene);
    // Peeling rasterises the front layer anyway: it then also stores the surface, and
    // `shade` lights it once per pixel instead of rasterising the mesh a third time and
    // shading hidden fragments. The same floats in, the same colour out (tested bit for
    // bit against SurfaceShading::forward); only with 32f depth, whose texels are the
    // fragments' exact depths (at 16 or 24 bits the front layer's visibility would be
    // resolved coarser than the shading's).
    const bool deferred = !by_facing && backlight_term &&
                          shading == SurfaceShading::deferred &&
                          p.depth_precision == "32f";

    // Step 0 (Sec. 3.1, Eq. 3.5): per-vertex AO; culled unless the ambient term reads it.
    add_ambient_occlusion(plan, scene, p.ao_rays,
                          "bake (or load cached) per-vertex AO, Eq. 3.5");
    // By facing, the first layer is `shade`'s own depth buffer (exact floats).
    plan.create("front_depth", by_facing ? ResourceFormat::depth32f : depth);
    plan.create("second_depth", depth);
    plan.create("smoothed_depth", ResourceFormat::r32f);
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);

    if (!by_facing) {
        // Step 1 (Sec. 3.1): depth of the nearest surface, read by the peel (and,
        // deferred, the surface that `shade` lights).
        Pass front{"front_depth", "depth of the first layer", PassKind::draw_mesh,
                   depth_only};
        front.writes = {"front_depth"};
        front.uniforms = camera;
        if (deferred) {
            plan.create("front_surface", ResourceFormat::rgba32f);
            front.purpose = "depth, interpolated normal and AO of the first layer";
            front.shader.fragment = "techniques/empirical/shaders/front_surface.frag";
            front.writes = {"front_surface", "front_depth"};
            if (ambient_term) {
                front.shader.defines.push_back("WITH_AMBIENT_OCCLUSION");
                front.reads.push_back({kAmbientOcclusionStream, ""});
            }
        }
        plan.add(front);
    }

    const std::string kernel_define = "KERNEL_SIZE " + std::to_string(p.blur_kernel);
    std::string back_layer;
    if (backlight_term) {
        if (by_facing) {
            Pass back{
                "second_layer",
                "the surface behind the first: nearest back face of the closed mesh",
                PassKind::draw_mesh, depth_only};
            back.writes = {"second_depth"};
            back.uniforms = camera;
            back.cull = FaceCulling::front;
            plan.add(back);
        } else {
            // Step 2 (App. B): the second layer by depth peeling.
            Pass peel{"second_layer",
                      "depth peeling: nearest depth behind front + epsilon",
                      PassKind::draw_mesh,
                      {mesh_vert, "techniques/empirical/shaders/peel.frag", {invariant}}};
            peel.reads = {{"front_depth", ""}};
            peel.writes = {"second_depth"};
            peel.uniforms = with_uniforms(
                camera,
                {{"u_epsilon", static_cast<float>(peel_epsilon(p.depth_precision))}});
            plan.add(peel);
        }
        back_layer = "second_depth";

        if (smoothing) {
            // Step 3 (App. C.2.2): depth-aware smoothing of the back layer. In full mode
            // with blur_kernel = 1 this runs a 1x1 kernel, an exact copy. By facing,
            // `shade` smooths per fragment instead (cheaper than a full-screen pass on
            // llvmpipe at every mesh size measured), so nothing reads this pass's output
            // and it runs only when asked for (the explorer's view of the smoothed
            // layer) or in full mode.
            const int size = p.blur_kernel;
            Pass smooth{"smooth_back_layer",
                        "depth-aware " + std::to_string(size) + "x" +
                            std::to_string(size) +
                            " smoothing of the second layer (Eq. C.1)",
                        PassKind::fullscreen,
                        {"gl/shaders/fullscreen.vert",
                         "techniques/empirical/shaders/smooth_depth.frag",
                         {kernel_define}}};
            smooth.reads = {{"second_depth", "back_depth"}};
            smooth.writes = {"smoothed_depth"};
            smooth.uniforms = {{"u_falloff", static_cast<float>(kSmoothingFalloff)}};
            plan.add(smooth);
            if (!by_facing) back_layer = "smoothed_depth";
        }
    }

    // Step 4 (Eq. 3.6): shading, one variant per set of live terms.
    Pass shade{"shade",
               "Eq. 3.6: ambient*AO + diffuse + specular + backlight(thickness)",
               PassKind::draw_mesh,
               {mesh_vert, "techniques/empirical/shaders/shade.frag", {invariant}}};
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
        if (!deferred) shade.reads.push_back({kAmbientOcclusionStream, ""});
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
        if (by_facing && smoothing) {
            shade.purpose += ", smoothing the second layer per fragment (Eq. C.1)";
            shade.shader.defines.push_back("SMOOTH_IN_SHADE");
            shade.shader.defines.push_back(kernel_define);
            u.push_back({"u_falloff", static_cast<float>(kSmoothingFalloff)});
        }
    }
    shade.uniforms = deferred ? u : with_uniforms(camera, u);
    // By facing, the shading pass's depth buffer is the first layer (the explorer shows
    // it under that name).
    shade.writes = deferred    ? std::vector<std::string>{"colour"}
                   : by_facing ? std::vector<std::string>{"colour", "front_depth"}
                               : std::vector<std::string>{"colour", "shade_depth"};
    if (by_facing) shade.cull = FaceCulling::back;
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
    plan.set_output("colour");
}

}  // namespace lucent::empirical
