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

namespace {

// What every stage reads, derived once from the scene and the knobs.
struct FrameInputs {
    FrameInputs(const Scene& scene, bool full, SurfaceShading shading);

    const Scene& scene;
    const Params p;
    const glm::vec3 light_ambient;
    // Which terms of Eq. 3.6 can change the image (all of them in full mode).
    const bool ambient_term, backlight_term, smoothing;
    const ResourceFormat depth;
    const std::vector<Uniform> camera;
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
    const bool by_facing;
    // Peeling rasterises the front layer anyway: it then also stores the surface, and
    // `shade` lights it once per pixel instead of rasterising the mesh a third time and
    // shading hidden fragments. The same floats in, the same colour out (tested bit for
    // bit against SurfaceShading::forward); only with 32f depth, whose texels are the
    // fragments' exact depths (at 16 or 24 bits the front layer's visibility would be
    // resolved coarser than the shading's).
    const bool deferred;
    const std::string kernel_define;
};

FrameInputs::FrameInputs(const Scene& scene, bool full, SurfaceShading shading)
    : scene(scene),
      p(params(scene)),
      light_ambient(scene.light.ambient),
      ambient_term(full || (p.ambient != 0.0 && light_ambient != glm::vec3(0.0f))),
      backlight_term(full || p.backlight != 0.0),
      smoothing(backlight_term && (full || p.blur_kernel > 1)),
      depth(depth_format(p.depth_precision)),
      camera(mesh_transform_uniforms(scene.camera.view(), scene.camera.projection())),
      by_facing(p.layer_method == "auto" && facing_separates_layers(scene)),
      deferred(!by_facing && backlight_term && shading == SurfaceShading::deferred &&
               p.depth_precision == "32f"),
      kernel_define("KERNEL_SIZE " + std::to_string(p.blur_kernel)) {}

void create_resources(PlanBuilder& plan, const FrameInputs& f) {
    // By facing, the first layer is `shade`'s own depth buffer (exact floats).
    plan.create("front_depth", f.by_facing ? ResourceFormat::depth32f : f.depth);
    plan.create("second_depth", f.depth);
    plan.create("smoothed_depth", ResourceFormat::r32f);
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);
}

// Step 1 (Sec. 3.1): depth of the nearest surface, read by the peel (and,
// deferred, the surface that `shade` lights).
void add_front_layer(PlanBuilder& plan, const FrameInputs& f) {
    Pass front{"front_depth", "depth of the first layer", PassKind::draw_mesh,
               f.depth_only};
    front.writes = {"front_depth"};
    front.uniforms = f.camera;
    if (f.deferred) {
        plan.create("front_surface", ResourceFormat::rgba32f);
        front.purpose = "depth, interpolated normal and AO of the first layer";
        front.shader.fragment = "techniques/empirical/shaders/front_surface.frag";
        front.writes = {"front_surface", "front_depth"};
        if (f.ambient_term) {
            front.shader.defines.push_back("WITH_AMBIENT_OCCLUSION");
            front.reads.push_back({kAmbientOcclusionStream, ""});
        }
    }
    plan.add(front);
}

// By facing, the second layer needs no peel: it is the nearest back face.
void add_nearest_back_face(PlanBuilder& plan, const FrameInputs& f) {
    Pass back{"second_layer",
              "the surface behind the first: nearest back face of the closed mesh",
              PassKind::draw_mesh, f.depth_only};
    back.writes = {"second_depth"};
    back.uniforms = f.camera;
    back.cull = FaceCulling::front;
    plan.add(back);
}

// Step 2 (App. B): the second layer by depth peeling.
void add_peeled_second_layer(PlanBuilder& plan, const FrameInputs& f) {
    Pass peel{"second_layer",
              "depth peeling: nearest depth behind front + epsilon",
              PassKind::draw_mesh,
              {f.mesh_vert, "techniques/empirical/shaders/peel.frag", {f.invariant}}};
    peel.reads = {{"front_depth", ""}};
    peel.writes = {"second_depth"};
    peel.uniforms = with_uniforms(
        f.camera, {{"u_epsilon", static_cast<float>(peel_epsilon(f.p.depth_precision))}});
    plan.add(peel);
}

// Step 3 (App. C.2.2): depth-aware smoothing of the back layer. In full mode
// with blur_kernel = 1 this runs a 1x1 kernel, an exact copy. By facing,
// `shade` smooths per fragment instead (cheaper than a full-screen pass on
// llvmpipe at every mesh size measured), so nothing reads this pass's output
// and it runs only when asked for (the explorer's view of the smoothed
// layer) or in full mode.
void add_smoothed_back_layer(PlanBuilder& plan, const FrameInputs& f) {
    const int size = f.p.blur_kernel;
    Pass smooth{"smooth_back_layer",
                "depth-aware " + std::to_string(size) + "x" + std::to_string(size) +
                    " smoothing of the second layer (Eq. C.1)",
                PassKind::fullscreen,
                {"gl/shaders/fullscreen.vert",
                 "techniques/empirical/shaders/smooth_depth.frag",
                 {f.kernel_define}}};
    smooth.reads = {{"second_depth", "back_depth"}};
    smooth.writes = {"smoothed_depth"};
    smooth.uniforms = {{"u_falloff", static_cast<float>(kSmoothingFalloff)}};
    plan.add(smooth);
}

// The second layer, and its smoothing where asked for; returns the layer that `shade`
// reads as the back depth.
std::string add_back_layer(PlanBuilder& plan, const FrameInputs& f) {
    if (f.by_facing)
        add_nearest_back_face(plan, f);
    else
        add_peeled_second_layer(plan, f);
    if (!f.smoothing) return "second_depth";
    add_smoothed_back_layer(plan, f);
    return f.by_facing ? "second_depth" : "smoothed_depth";
}

// The shade pass's backlight term: the thickness from the back layer (Eq. 3.6).
void add_backlight_inputs(Pass& shade, std::vector<Uniform>& u, const FrameInputs& f,
                          const std::string& back_layer) {
    const Params& p = f.p;
    shade.shader.defines.push_back("WITH_BACKLIGHT");
    shade.reads.push_back({back_layer, "back_depth"});
    u.push_back({"u_backlight", static_cast<float>(p.backlight)});
    u.push_back({"u_thickness_exponent", static_cast<float>(p.thickness_exponent)});
    u.push_back({"u_diffuse_weight", static_cast<float>(p.diffuse_weight)});
    u.push_back({"u_near", f.scene.camera.near_plane});
    u.push_back({"u_far", f.scene.camera.far_plane});
    u.push_back({"u_diameter", f.scene.bounds.diameter()});
    if (f.by_facing && f.smoothing) {
        shade.purpose += ", smoothing the second layer per fragment (Eq. C.1)";
        shade.shader.defines.push_back("SMOOTH_IN_SHADE");
        shade.shader.defines.push_back(f.kernel_define);
        u.push_back({"u_falloff", static_cast<float>(kSmoothingFalloff)});
    }
}

// Step 4 (Eq. 3.6): shading, one variant per set of live terms.
void add_shade(PlanBuilder& plan, const FrameInputs& f, const std::string& back_layer) {
    const Scene& scene = f.scene;
    const Params& p = f.p;
    Pass shade{"shade",
               "Eq. 3.6: ambient*AO + diffuse + specular + backlight(thickness)",
               PassKind::draw_mesh,
               {f.mesh_vert, "techniques/empirical/shaders/shade.frag", {f.invariant}}};
    if (f.deferred) {
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
    if (f.ambient_term) {
        shade.shader.defines.push_back("WITH_AMBIENT_OCCLUSION");
        if (!f.deferred) shade.reads.push_back({kAmbientOcclusionStream, ""});
        u.push_back({"u_ambient", static_cast<float>(p.ambient)});
        u.push_back({"u_light_ambient", f.light_ambient});
    }
    if (f.backlight_term) add_backlight_inputs(shade, u, f, back_layer);
    shade.uniforms = f.deferred ? u : with_uniforms(f.camera, u);
    // By facing, the shading pass's depth buffer is the first layer (the explorer shows
    // it under that name).
    shade.writes = f.deferred    ? std::vector<std::string>{"colour"}
                   : f.by_facing ? std::vector<std::string>{"colour", "front_depth"}
                                 : std::vector<std::string>{"colour", "shade_depth"};
    if (f.by_facing) shade.cull = FaceCulling::back;
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan, SurfaceShading shading) {
    const FrameInputs f(scene, plan.full(), shading);
    // Step 0 (Sec. 3.1, Eq. 3.5): per-vertex AO; culled unless the ambient term reads it.
    add_ambient_occlusion(plan, scene, f.p.ao_rays,
                          "bake (or load cached) per-vertex AO, Eq. 3.5");
    create_resources(plan, f);
    if (!f.by_facing) add_front_layer(plan, f);
    std::string back_layer;
    if (f.backlight_term) back_layer = add_back_layer(plan, f);
    add_shade(plan, f, back_layer);
    plan.set_output("colour");
}

}  // namespace lucent::empirical
