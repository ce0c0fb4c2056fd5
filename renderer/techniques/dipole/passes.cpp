// What the dipole technique adds to a frame plan (Chang et al. Fig. 1, Sec. 3-4):
//   ambient_occlusion    per-vertex AO bake                 -> vertex_ao      (ambient)
//   atlas_positions      CPU surfel atlas: xyz mm, area     -> atlas_position
//   (subsurface) atlas_normals        CPU surfel atlas: normals          -> atlas_normal
//   (subsurface) light_view           mesh from the light (ortho)        -> light_depth
//   [, light_flux,
//                                                              light_position (hybrid)]
//   irradiance           E A per atlas texel, with V        -> irradiance level 0
//   irradiance_mips      exact 2x2 box means                -> irradiance levels 1..
//   ring_pattern         CPU local pattern (hybrid)         -> ring_pattern
//   samples              inverse-CDF descent, N samples     -> samples
//   surface              nearest surface: position, normal,  -> surface_* (deferred)
//                        AO, eye normal
//   translucency         Eq. 11 (+ local, ambient, tone map, specular) -> colour, once
//                        per covered pixel
// Exact prunes: Id = 0 or nothing scatters (no subsurface passes), ks = 0 or Is = 0 (no
// specular), eta = 1 (no Fresnel), hybrid off or no channel with an Rp (no local part),
// ka Ia = 0 (no AO). In full mode every pass runs with the pruned terms at weight 0.
#include <memory>
#include <mutex>

#include "common/number_text.h"
#include "renderer/core/light_view.h"
#include "renderer/techniques/ambient_occlusion_pass.h"
#include "renderer/techniques/deferred_surface.h"
#include "renderer/techniques/dipole/atlas.h"
#include "renderer/techniques/dipole/dipole.h"

namespace lucent::dipole {
namespace {

// The atlas is built once per plan, when the first of its two uploads asks for it (and
// only when the executor's copy is stale: the content hash differs).
struct LazyAtlas {
    std::shared_ptr<const Mesh> mesh;
    double scale = 1.0;
    int resolution = 0;
    std::once_flag once;
    SurfaceAtlas atlas;
    const SurfaceAtlas& get() {
        std::call_once(once,
                       [&] { atlas = build_surface_atlas(*mesh, scale, resolution); });
        return atlas;
    }
};

TextureData texels_of(const std::vector<glm::vec4>& values, int width, int height) {
    TextureData data;
    data.size = {width, height, 1};
    std::vector<float> level(values.size() * 4);
    for (std::size_t i = 0; i < values.size(); ++i)
        for (int c = 0; c < 4; ++c) level[4 * i + c] = values[i][c];
    data.levels.push_back(std::move(level));
    return data;
}

double surface_area_mm2(const Mesh& mesh, double scale) {
    double area = 0.0;
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]),
            c(mesh.positions[t.z]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return area * scale * scale;
}

// The profile's constants per channel (dipole.glsl); zr = zv = 1 where nothing
// scatters so that the shader never divides by 0.
std::vector<Uniform> profile_uniforms(const Params& p, const Material& material,
                                      const DipoleRgb& dipole, const HybridSplit& split,
                                      double scale) {
    glm::vec3 rd_scale(0.0f), sigma_tr(0.0f), z_real(1.0f), z_virtual(1.0f), rp(-1.0f);
    for (int c = 0; c < 3; ++c) {
        if (!dipole[c].scatters()) continue;
        rd_scale[c] = float(dipole[c].albedo() / (4.0 * kPi));
        sigma_tr[c] = float(dipole[c].sigma_tr());
        z_real[c] = float(dipole[c].z_real());
        z_virtual[c] = float(dipole[c].z_virtual());
        if (split.rp[c]) rp[c] = float(*split.rp[c]);
    }
    return {{"u_rd_scale", rd_scale},
            {"u_sigma_tr", sigma_tr},
            {"u_z_real", z_real},
            {"u_z_virtual", z_virtual},
            {"u_rp", rp},
            {"u_hybrid_k", float(p.hybrid_k)},
            {"u_eta", float(material.eta)},
            {"u_scale", float(scale)}};
}

// The coarsest level of the atlas's mip pyramid, where the inverse-CDF descent starts.
int top_mip_level(int atlas) {
    int level = 0;
    while ((1 << level) < atlas) ++level;
    return level;
}

// The side of the square texture that holds the N samples.
int sample_side(int samples) {
    int side = 1;
    while (side * side < samples) ++side;
    return side;
}

// What every stage reads, derived once from the scene and the knobs.
struct FrameInputs {
    FrameInputs(const Scene& scene, bool full);

    const Scene& scene;
    const Params p;
    const Material material;
    const DipoleRgb dipole;
    const Mesh& mesh;
    const double scale;

    // Which terms can change the image (all of them in full mode).
    const bool subsurface;
    const HybridSplit split;
    const bool local, fresnel, ambient, specular, tone_map;

    const std::vector<Uniform> camera;
    const std::string mesh_vert = "techniques/shaders/mesh.vert";
    const glm::vec3 light_object;
    const std::vector<Uniform> profile;

    const int atlas, light_map;
    const int top_level, side;
    const RingPattern pattern;

    void add_fresnel_define(ShaderDesc& shader) const {
        if (fresnel) shader.defines.push_back("WITH_FRESNEL");
    }
};

FrameInputs::FrameInputs(const Scene& scene, bool full)
    : scene(scene),
      p(params(scene)),
      material(material_of(p)),
      dipole(material),
      mesh(*scene.mesh),
      scale(model_scale(mesh, p.model_size)),
      subsurface(full || has_subsurface_term(p, scene)),
      split(p.hybrid ? make_hybrid_split(dipole, p.importance_bound, p.hybrid_k)
                     : HybridSplit{}),
      local(subsurface && (full || split.any_local())),
      fresnel(full || material.eta != 1.0),
      ambient(full || has_ambient_term(p, scene)),
      specular(full || has_specular_term(p, scene)),
      tone_map(p.tone_map == "reinhard"),
      camera(mesh_transform_uniforms(scene.camera.view(), scene.camera.projection())),
      light_object(glm::vec3(light_in_object_space(scene))),
      profile(profile_uniforms(p, material, dipole, split, scale)),
      atlas(p.atlas_resolution),
      light_map(p.light_map_resolution),
      top_level(top_mip_level(atlas)),
      side(sample_side(p.samples)),
      pattern(make_ring_pattern(dipole, split, p.rings, p.ring_samples)) {}

void create_resources(PlanBuilder& plan, const FrameInputs& f) {
    const int atlas = f.atlas, light_map = f.light_map;
    plan.create(texture_2d("atlas_position", ResourceFormat::rgba32f, atlas, atlas));
    plan.create(texture_2d("atlas_normal", ResourceFormat::rgba32f, atlas, atlas));
    plan.create(
        texture_2d("light_depth", ResourceFormat::depth32f, light_map, light_map));
    plan.create(texture_2d("light_flux", ResourceFormat::r32f, light_map, light_map));
    plan.create(
        texture_2d("light_position", ResourceFormat::rgba32f, light_map, light_map));
    plan.create(texture_2d("irradiance", ResourceFormat::r32f, atlas, atlas, 0));
    plan.create(texture_2d("ring_pattern", ResourceFormat::rgba32f,
                           int(f.pattern.offset.size()), 1));
    plan.create(texture_2d("samples", ResourceFormat::rgba32f, f.side, f.side));
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);
}

// Stage 0 (Sec. 3, our atlas): the surfel atlas, uploaded when the mesh, the
// model size or the resolution changes.
void add_atlas_uploads(PlanBuilder& plan, const FrameInputs& f) {
    const int atlas = f.atlas;
    auto lazy = std::make_shared<LazyAtlas>();
    lazy->mesh = f.scene.mesh;
    lazy->scale = f.scale;
    lazy->resolution = atlas;
    const std::string atlas_hash = f.mesh.content_hash + "-s" +
                                   common::full_precision_text(f.scale) + "-a" +
                                   std::to_string(atlas);
    Pass positions{"atlas_positions",
                   "surfel atlas: equal-area texels, xyz mm and area mm^2",
                   PassKind::upload};
    positions.writes = {"atlas_position"};
    positions.data = {atlas_hash + "-p", [lazy, atlas](const ProduceOptions&) {
                          return texels_of(lazy->get().position_area, atlas, atlas);
                      }};
    plan.add(positions);
    Pass normals{"atlas_normals", "surfel atlas: facet normals", PassKind::upload};
    normals.writes = {"atlas_normal"};
    normals.data = {atlas_hash + "-n", [lazy, atlas](const ProduceOptions&) {
                        return texels_of(lazy->get().normal, atlas, atlas);
                    }};
    plan.add(normals);
}

// The light view (orthographic, fitted to the bounding sphere): depth for the
// visibility the paper leaves out; flux and position for the hybrid's local part.
void add_light_view(PlanBuilder& plan, const FrameInputs& f, const LightView& light) {
    Pass light_pass{"light_view",
                    f.local ? "mesh from the key light: depth, flux phi and position "
                              "(Sec. 4.2)"
                            : "mesh from the key light: depth for visibility",
                    PassKind::draw_mesh,
                    {f.mesh_vert, "techniques/dipole/shaders/light_view.frag", {}}};
    light_pass.writes = {"light_depth"};
    std::vector<Uniform> light_uniforms =
        mesh_transform_uniforms(light.view, light.projection);
    if (f.local) {
        light_pass.shader.defines.push_back("WITH_LOCAL");
        f.add_fresnel_define(light_pass.shader);
        light_pass.writes = {"light_flux", "light_position", "light_depth"};
        light_uniforms.push_back({"u_light_object", f.light_object});
        light_uniforms = with_uniforms(light_uniforms, f.profile);
    }
    light_pass.uniforms = light_uniforms;
    plan.add(light_pass);
}

// Stage 1 (Eqs. 4-7): texel masses E A with Fresnel and visibility.
void add_irradiance(PlanBuilder& plan, const FrameInputs& f, const LightView& light) {
    const float texel_object = 2.0f * light.radius / float(f.light_map);
    Pass irradiance{
        "irradiance",
        "E A per atlas texel: pi Ft(eta, N.L) max(N.L, 0) V (Eqs. 4-7)",
        PassKind::fullscreen,
        {"gl/shaders/fullscreen.vert", "techniques/dipole/shaders/irradiance.frag", {}}};
    f.add_fresnel_define(irradiance.shader);
    irradiance.reads = {{"atlas_position", ""},
                        {"atlas_normal", ""},
                        {"light_depth", "", {TexelFilter::nearest}}};
    irradiance.writes = {"irradiance"};
    irradiance.uniforms =
        with_uniforms({{"u_light_view_projection", light.view_projection},
                       {"u_light_object", f.light_object},
                       {"u_normal_offset", 1.5f * texel_object},
                       {"u_depth_bias", 0.5f / float(f.light_map)}},
                      f.profile);
    plan.add(irradiance);

    Pass mips{"irradiance_mips", "mip pyramid of the texel masses (exact 2x2 box)",
              PassKind::build_mips};
    mips.writes = {"irradiance"};
    plan.add(mips);
}

// Stage 2 (Sec. 3, Fig. 2b): N stratified samples by the inverse CDF.
void add_samples(PlanBuilder& plan, const FrameInputs& f) {
    const Params& p = f.p;
    Pass samples{
        "samples",
        "inverse-CDF descent of the mip pyramid: " + std::to_string(p.samples) +
            " stratified samples",
        PassKind::fullscreen,
        {"gl/shaders/fullscreen.vert", "techniques/dipole/shaders/samples.frag", {}}};
    samples.reads = {{"irradiance", ""}, {"atlas_position", ""}};
    samples.writes = {"samples"};
    samples.uniforms = {{"u_sample_count", p.samples},
                        {"u_sample_side", f.side},
                        {"u_top_level", f.top_level},
                        {"u_offset", float(stratification_offset(p.sample_seed))}};
    plan.add(samples);
}

// The hybrid's local pattern on the light plane, uploaded when it changes.
void add_ring_pattern(PlanBuilder& plan, const FrameInputs& f) {
    const RingPattern& pattern = f.pattern;
    const std::vector<float> texels = [&] {
        std::vector<float> t;
        for (std::size_t k = 0; k < pattern.offset.size(); ++k) {
            t.push_back(float(pattern.offset[k].x));
            t.push_back(float(pattern.offset[k].y));
            t.push_back(float(pattern.weight[k]));
            t.push_back(0.0f);
        }
        return t;
    }();
    std::string hash = "ring";
    for (float v : texels) hash += "," + common::full_precision_text(v);
    Pass ring{"ring_pattern",
              "local pattern: " + std::to_string(pattern.offset.size()) +
                  " equal-mass samples on the light plane",
              PassKind::upload};
    ring.writes = {"ring_pattern"};
    const int count = int(pattern.offset.size());
    ring.data = {hash, [texels, count](const ProduceOptions&) {
                     TextureData data;
                     data.size = {count, 1, 1};
                     data.levels = {texels};
                     return data;
                 }};
    plan.add(ring);
}

// The purpose names what was pruned and why, so --explain accounts for every culled
// pass.
std::string pruned_note(const FrameInputs& f) {
    std::string pruned;
    const auto prune = [&](bool kept, const char* what) {
        if (!kept) pruned += (pruned.empty() ? "; pruned: " : ", ") + std::string(what);
    };
    prune(f.subsurface, "subsurface passes (Id = 0 or nothing scatters)");
    prune(!f.subsurface || f.local, f.p.hybrid
                                        ? "local part (no channel has an Rp at this c)"
                                        : "local part (hybrid off)");
    prune(f.fresnel, "Fresnel (eta = 1)");
    prune(f.ambient, "ambient and AO (ka Ia = 0)");
    prune(f.specular, "specular (ks Is = 0)");
    return pruned;
}

// The translucency pass's inputs from the subsurface stages: the samples and, with the
// hybrid, the local part's light view and pattern.
void add_subsurface_inputs(Pass& shade, std::vector<Uniform>& u, const FrameInputs& f) {
    const Scene& scene = f.scene;
    shade.shader.defines.push_back("WITH_SUBSURFACE");
    shade.reads = {{"samples", ""}, {"irradiance", ""}};
    u.push_back({"u_light_diffuse", scene.light.diffuse});
    u.push_back({"u_sample_count", f.p.samples});
    u.push_back({"u_sample_side", f.side});
    u.push_back({"u_top_level", f.top_level});
    u.push_back({"u_texel_count", float(f.atlas) * float(f.atlas)});
    u = with_uniforms(u, f.profile);
    if (f.local) {
        const LightView light = scene_light_view(scene);
        shade.shader.defines.push_back("WITH_LOCAL");
        shade.reads.push_back({"light_flux", "", {TexelFilter::nearest}});
        shade.reads.push_back({"light_position", "", {TexelFilter::nearest}});
        shade.reads.push_back({"ring_pattern", ""});
        u.push_back({"u_ring_count", int(f.pattern.offset.size())});
        u.push_back({"u_light_view_projection", light.view_projection});
        u.push_back({"u_light_plane_mm", float(2.0 * light.radius * f.scale)});
    }
}

// Stage 3 (Eq. 11) and what follows it.
void add_translucency(PlanBuilder& plan, const FrameInputs& f, SurfaceShading shading) {
    const Scene& scene = f.scene;
    const Params& p = f.p;
    Pass shade{"translucency",
               "Eq. 11: Ft(eta, N.V) Id B / pi" +
                   std::string(f.local ? " (global + local)" : "") +
                   (f.ambient ? " + ambient" : "") + (f.tone_map ? ", Reinhard" : "") +
                   (f.specular ? " + Blinn-Phong" : "") + pruned_note(f),
               PassKind::draw_mesh,
               {f.mesh_vert, "techniques/dipole/shaders/translucency.frag", {}}};
    std::vector<Uniform> u = {{"u_light_direction", scene.light.direction},
                              {"u_eye_object", scene.camera.eye},
                              {"u_background", scene.background}};
    f.add_fresnel_define(shade.shader);
    if (f.subsurface) {
        add_subsurface_inputs(shade, u, f);
    } else {
        u.push_back({"u_eta", float(f.material.eta)});
    }
    if (f.ambient) {
        shade.shader.defines.push_back("WITH_AMBIENT");
        shade.reads.push_back({kAmbientOcclusionStream, ""});
        const glm::dvec3 colour = p.ambient * glm::dvec3(scene.light.ambient) *
                                  mean_fresnel_transmittance(f.material.eta) *
                                  f.dipole.total_reflectance();
        u.push_back({"u_ambient_colour", glm::vec3(colour)});
    }
    if (f.tone_map) {
        shade.shader.defines.push_back("TONE_MAP");
        u.push_back({"u_tone_key", float(p.tone_key)});
        u.push_back(
            {"u_tone_average_per_flux",
             float(tone_map_average(p, scene, 1.0, surface_area_mm2(f.mesh, f.scale)))});
    }
    if (f.specular) {
        shade.shader.defines.push_back("WITH_SPECULAR");
        u.push_back({"u_specular", float(p.specular)});
        u.push_back({"u_shininess", float(p.shininess)});
        u.push_back({"u_light_specular", scene.light.specular});
    }
    shade.uniforms = with_uniforms(f.camera, u);
    shade.writes = {"colour", "shade_depth"};
    if (shading == SurfaceShading::deferred)
        shade_deferred(plan, shade, f.camera, /*eye_normal=*/f.specular, f.ambient);
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan, SurfaceShading shading) {
    const FrameInputs f(scene, plan.full());
    // Ambient occlusion for the ambient term (as the other techniques).
    add_ambient_occlusion(plan, scene, f.p.ao_rays,
                          "bake (or load cached) per-vertex AO");
    create_resources(plan, f);
    if (f.subsurface) {
        add_atlas_uploads(plan, f);
        const LightView light = scene_light_view(scene);
        add_light_view(plan, f, light);
        add_irradiance(plan, f, light);
        add_samples(plan, f);
        if (f.local) add_ring_pattern(plan, f);
    }
    add_translucency(plan, f, shading);
    plan.set_output("colour");
}

}  // namespace lucent::dipole
