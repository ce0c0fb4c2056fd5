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

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan, SurfaceShading shading) {
    const Params p = params(scene);
    const Material material = material_of(p);
    const DipoleRgb dipole(material);
    const Mesh& mesh = *scene.mesh;
    const double scale = model_scale(mesh, p.model_size);
    const bool full = plan.full();

    // Which terms can change the image (all of them in full mode).
    const bool subsurface = full || has_subsurface_term(p, scene);
    const HybridSplit split =
        p.hybrid ? make_hybrid_split(dipole, p.importance_bound, p.hybrid_k)
                 : HybridSplit{};
    const bool local = subsurface && (full || split.any_local());
    const bool fresnel = full || material.eta != 1.0;
    const bool ambient = full || has_ambient_term(p, scene);
    const bool specular = full || has_specular_term(p, scene);
    const bool tone_map = p.tone_map == "reinhard";

    const glm::mat4 view = scene.camera.view();
    const std::vector<Uniform> camera =
        mesh_transform_uniforms(view, scene.camera.projection());
    const std::string mesh_vert = "techniques/shaders/mesh.vert";
    const glm::vec3 light_object = glm::vec3(light_in_object_space(scene));

    // The profile's constants per channel (dipole.glsl); zr = zv = 1 where nothing
    // scatters so that the shader never divides by 0.
    glm::vec3 rd_scale(0.0f), sigma_tr(0.0f), z_real(1.0f), z_virtual(1.0f), rp(-1.0f);
    for (int c = 0; c < 3; ++c) {
        if (!dipole[c].scatters()) continue;
        rd_scale[c] = float(dipole[c].albedo() / (4.0 * kPi));
        sigma_tr[c] = float(dipole[c].sigma_tr());
        z_real[c] = float(dipole[c].z_real());
        z_virtual[c] = float(dipole[c].z_virtual());
        if (split.rp[c]) rp[c] = float(*split.rp[c]);
    }
    const std::vector<Uniform> profile = {{"u_rd_scale", rd_scale},
                                          {"u_sigma_tr", sigma_tr},
                                          {"u_z_real", z_real},
                                          {"u_z_virtual", z_virtual},
                                          {"u_rp", rp},
                                          {"u_hybrid_k", float(p.hybrid_k)},
                                          {"u_eta", float(material.eta)},
                                          {"u_scale", float(scale)}};
    const auto fresnel_define = [&](ShaderDesc& shader) {
        if (fresnel) shader.defines.push_back("WITH_FRESNEL");
    };

    const int atlas = p.atlas_resolution, light_map = p.light_map_resolution;
    const int top_level = [&] {
        int level = 0;
        while ((1 << level) < atlas) ++level;
        return level;
    }();
    int side = 1;
    while (side * side < p.samples) ++side;
    const RingPattern pattern = make_ring_pattern(dipole, split, p.rings, p.ring_samples);

    // Ambient occlusion for the ambient term (as the other techniques).
    add_ambient_occlusion(plan, scene, p.ao_rays, "bake (or load cached) per-vertex AO");
    plan.create(texture_2d("atlas_position", ResourceFormat::rgba32f, atlas, atlas));
    plan.create(texture_2d("atlas_normal", ResourceFormat::rgba32f, atlas, atlas));
    plan.create(
        texture_2d("light_depth", ResourceFormat::depth32f, light_map, light_map));
    plan.create(texture_2d("light_flux", ResourceFormat::r32f, light_map, light_map));
    plan.create(
        texture_2d("light_position", ResourceFormat::rgba32f, light_map, light_map));
    plan.create(texture_2d("irradiance", ResourceFormat::r32f, atlas, atlas, 0));
    plan.create(texture_2d("ring_pattern", ResourceFormat::rgba32f,
                           int(pattern.offset.size()), 1));
    plan.create(texture_2d("samples", ResourceFormat::rgba32f, side, side));
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);

    if (subsurface) {
        // Stage 0 (Sec. 3, our atlas): the surfel atlas, uploaded when the mesh, the
        // model size or the resolution changes.
        auto lazy = std::make_shared<LazyAtlas>();
        lazy->mesh = scene.mesh;
        lazy->scale = scale;
        lazy->resolution = atlas;
        const std::string atlas_hash = mesh.content_hash + "-s" +
                                       common::full_precision_text(scale) + "-a" +
                                       std::to_string(atlas);
        Pass positions{"atlas_positions",
                       "surfel atlas: equal-area texels, xyz mm and area mm^2",
                       PassKind::upload};
        positions.writes = {"atlas_position"};
        positions.data = {atlas_hash + "-p", [lazy, atlas](const ProduceOptions&) {
                              return texels_of(lazy->get().position_area, atlas, atlas);
                          }};
        plan.add(positions);
        Pass normals{"atlas_normals", "surfel atlas: interpolated normals",
                     PassKind::upload};
        normals.writes = {"atlas_normal"};
        normals.data = {atlas_hash + "-n", [lazy, atlas](const ProduceOptions&) {
                            return texels_of(lazy->get().normal, atlas, atlas);
                        }};
        plan.add(normals);

        // The light view (orthographic, fitted to the bounding sphere): depth for the
        // visibility the paper leaves out; flux and position for the hybrid's local part.
        const LightView light = scene_light_view(scene);
        Pass light_pass{"light_view",
                        local ? "mesh from the key light: depth, flux phi and position "
                                "(Sec. 4.2)"
                              : "mesh from the key light: depth for visibility",
                        PassKind::draw_mesh,
                        {mesh_vert, "techniques/dipole/shaders/light_view.frag", {}}};
        light_pass.writes = {"light_depth"};
        std::vector<Uniform> light_uniforms =
            mesh_transform_uniforms(light.view, light.projection);
        if (local) {
            light_pass.shader.defines.push_back("WITH_LOCAL");
            fresnel_define(light_pass.shader);
            light_pass.writes = {"light_flux", "light_position", "light_depth"};
            light_uniforms.push_back({"u_light_object", light_object});
            light_uniforms = with_uniforms(light_uniforms, profile);
        }
        light_pass.uniforms = light_uniforms;
        plan.add(light_pass);

        // Stage 1 (Eqs. 4-7): texel masses E A with Fresnel and visibility.
        const float texel_object = 2.0f * light.radius / float(light_map);
        Pass irradiance{"irradiance",
                        "E A per atlas texel: pi Ft(eta, N.L) max(N.L, 0) V (Eqs. 4-7)",
                        PassKind::fullscreen,
                        {"gl/shaders/fullscreen.vert",
                         "techniques/dipole/shaders/irradiance.frag",
                         {}}};
        fresnel_define(irradiance.shader);
        irradiance.reads = {{"atlas_position", ""},
                            {"atlas_normal", ""},
                            {"light_depth", "", {TexelFilter::nearest}}};
        irradiance.writes = {"irradiance"};
        irradiance.uniforms =
            with_uniforms({{"u_light_view_projection", light.view_projection},
                           {"u_light_object", light_object},
                           {"u_normal_offset", 1.5f * texel_object},
                           {"u_depth_bias", 0.5f / float(light_map)}},
                          profile);
        plan.add(irradiance);

        Pass mips{"irradiance_mips", "mip pyramid of the texel masses (exact 2x2 box)",
                  PassKind::build_mips};
        mips.writes = {"irradiance"};
        plan.add(mips);

        // Stage 2 (Sec. 3, Fig. 2b): N stratified samples by the inverse CDF.
        Pass samples{
            "samples",
            "inverse-CDF descent of the mip pyramid: " + std::to_string(p.samples) +
                " stratified samples",
            PassKind::fullscreen,
            {"gl/shaders/fullscreen.vert", "techniques/dipole/shaders/samples.frag", {}}};
        samples.reads = {{"irradiance", ""}, {"atlas_position", ""}};
        samples.writes = {"samples"};
        samples.uniforms = {{"u_sample_count", p.samples},
                            {"u_sample_side", side},
                            {"u_top_level", top_level},
                            {"u_offset", float(stratification_offset(p.sample_seed))}};
        plan.add(samples);

        if (local) {
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
    }

    // Stage 3 (Eq. 11) and what follows it. The purpose names what was pruned and why,
    // so --explain accounts for every culled pass.
    std::string pruned;
    const auto prune = [&](bool kept, const char* what) {
        if (!kept) pruned += (pruned.empty() ? "; pruned: " : ", ") + std::string(what);
    };
    prune(subsurface, "subsurface passes (Id = 0 or nothing scatters)");
    prune(!subsurface || local, p.hybrid ? "local part (no channel has an Rp at this c)"
                                         : "local part (hybrid off)");
    prune(fresnel, "Fresnel (eta = 1)");
    prune(ambient, "ambient and AO (ka Ia = 0)");
    prune(specular, "specular (ks Is = 0)");
    Pass shade{"translucency",
               "Eq. 11: Ft(eta, N.V) Id B / pi" +
                   std::string(local ? " (global + local)" : "") +
                   (ambient ? " + ambient" : "") + (tone_map ? ", Reinhard" : "") +
                   (specular ? " + Blinn-Phong" : "") + pruned,
               PassKind::draw_mesh,
               {mesh_vert, "techniques/dipole/shaders/translucency.frag", {}}};
    std::vector<Uniform> u = {{"u_light_direction", scene.light.direction},
                              {"u_eye_object", scene.camera.eye},
                              {"u_background", scene.background}};
    fresnel_define(shade.shader);
    if (subsurface) {
        shade.shader.defines.push_back("WITH_SUBSURFACE");
        shade.reads = {{"samples", ""}, {"irradiance", ""}};
        u.push_back({"u_light_diffuse", scene.light.diffuse});
        u.push_back({"u_sample_count", p.samples});
        u.push_back({"u_sample_side", side});
        u.push_back({"u_top_level", top_level});
        u.push_back({"u_texel_count", float(atlas) * float(atlas)});
        u = with_uniforms(u, profile);
        if (local) {
            const LightView light = scene_light_view(scene);
            shade.shader.defines.push_back("WITH_LOCAL");
            shade.reads.push_back({"light_flux", "", {TexelFilter::nearest}});
            shade.reads.push_back({"light_position", "", {TexelFilter::nearest}});
            shade.reads.push_back({"ring_pattern", ""});
            u.push_back({"u_ring_count", int(pattern.offset.size())});
            u.push_back({"u_light_view_projection", light.view_projection});
            u.push_back({"u_light_plane_mm", float(2.0 * light.radius * scale)});
        }
    } else {
        u.push_back({"u_eta", float(material.eta)});
    }
    if (ambient) {
        shade.shader.defines.push_back("WITH_AMBIENT");
        shade.reads.push_back({kAmbientOcclusionStream, ""});
        const glm::dvec3 colour = p.ambient * glm::dvec3(scene.light.ambient) *
                                  mean_fresnel_transmittance(material.eta) *
                                  dipole.total_reflectance();
        u.push_back({"u_ambient_colour", glm::vec3(colour)});
    }
    if (tone_map) {
        shade.shader.defines.push_back("TONE_MAP");
        u.push_back({"u_tone_key", float(p.tone_key)});
        u.push_back(
            {"u_tone_average_per_flux",
             float(tone_map_average(p, scene, 1.0, surface_area_mm2(mesh, scale)))});
    }
    if (specular) {
        shade.shader.defines.push_back("WITH_SPECULAR");
        u.push_back({"u_specular", float(p.specular)});
        u.push_back({"u_shininess", float(p.shininess)});
        u.push_back({"u_light_specular", scene.light.specular});
    }
    shade.uniforms = with_uniforms(camera, u);
    shade.writes = {"colour", "shade_depth"};
    if (shading == SurfaceShading::deferred)
        shade_deferred(plan, shade, camera, /*eye_normal=*/specular, ambient);
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
    plan.set_output("colour");
}

}  // namespace lucent::dipole
