// What the htsm technique adds to a frame plan (Shopf Sec. 4.3, README.md):
//   density_volume   CPU volume, by content hash  -> htsm_density (3-D r32f)   (a march)
//   phase_table      CPU Henyey-Greenstein table  -> htsm_phase (N_f x 1)      (g != 0)
//   light_view       mesh from the key light      -> htsm_irradiance, htsm_texcoord
//                                                    [, htsm_normal full only],
//                                                    light_depth
//   irradiance_mips, texcoord_mips  exact 2x2 box means                       (a lod > 0)
//   shade            mesh from the camera         -> colour
// Pruned: no transport (Tc = 0 or Id = 0) drops everything but the shadow depth; a
// constant density (or kappa = 0) drops the volume and the march; g = 0 the table; no
// ring with a lod above 0 the mips; no diffuse or specular the shadow read.
#include <cstdio>

#include "common/number_text.h"
#include "renderer/techniques/htsm/htsm.h"

namespace lucent::htsm {
namespace {

std::string number(double value) { return common::nine_digit_text(value); }

bool any_coarse_lod(const std::vector<PatternSample>& samples) {
    bool coarse = false;
    for (const PatternSample& s : samples) coarse |= s.lod > 0.0;
    return coarse;
}

// What every stage reads, derived once from the scene and the knobs.
struct FrameInputs {
    FrameInputs(const Scene& scene, bool full);

    const Scene& scene;
    const Params p;
    const Geometry g;
    const bool full;
    const bool transport, surface, march, table;
    const std::vector<PatternSample> samples;
    const bool mips;
    const int wl;

    const std::string mesh_vert = "techniques/shaders/mesh.vert";
    const LightView& light;
    const std::vector<Uniform> box;
};

FrameInputs::FrameInputs(const Scene& scene, bool full)
    : scene(scene),
      p(params(scene)),
      g(geometry(scene, p)),
      full(full),
      transport(full || has_transport(p, scene)),
      surface(full || has_surface(p, scene)),
      march(transport && scene.density && (full || !density_is_constant(p, scene))),
      table(transport && (full || p.phase_g != 0.0)),
      samples(pattern(p, g)),
      mips(transport && (full || any_coarse_lod(samples))),
      wl(p.light_map_size),
      light(g.light),
      box({{"u_box_min", glm::vec3(g.box_min)},
           {"u_box_extent", glm::vec3(g.box_extent)}}) {}

void create_resources(PlanBuilder& plan, const FrameInputs& f) {
    const Scene& scene = f.scene;
    const int wl = f.wl;
    plan.create(texture_2d("light_depth", ResourceFormat::depth32f, wl, wl));
    plan.create(
        texture_2d("htsm_irradiance", ResourceFormat::rgba32f, wl, wl, f.mips ? 0 : 1));
    plan.create(
        texture_2d("htsm_texcoord", ResourceFormat::rgba32f, wl, wl, f.mips ? 0 : 1));
    plan.create(texture_2d("htsm_normal", ResourceFormat::rgba32f, wl, wl));
    plan.create(texture_2d("htsm_phase", ResourceFormat::r32f, f.p.phase_table_size, 1));
    if (scene.density)
        plan.create(texture_3d("htsm_density", ResourceFormat::r32f,
                               scene.density->size.x, scene.density->size.y,
                               scene.density->size.z));
    plan.create("colour", ResourceFormat::rgba32f);
    plan.create("shade_depth", ResourceFormat::depth32f);
}

void add_density_volume(PlanBuilder& plan, const FrameInputs& f) {
    const auto density = f.scene.density;
    Pass volume{"density_volume",
                "density volume " + density->spec + " (" +
                    std::to_string(density->size.x) + "^3 voxels)",
                PassKind::upload};
    volume.writes = {"htsm_density"};
    volume.data = {"density-" + density->content_hash, [density](const ProduceOptions&) {
                       TextureData data;
                       data.size = density->size;
                       data.levels = {density->voxels};
                       return data;
                   }};
    plan.add(volume);
}

void add_phase_table(PlanBuilder& plan, const FrameInputs& f) {
    const int nf = f.p.phase_table_size;
    const double gg = f.p.phase_g;
    Pass phase_pass{"phase_table",
                    "Henyey-Greenstein g = " + number(gg) + ", f(1) = 1, " +
                        std::to_string(nf) + " entries (Sec. 4.3.4)",
                    PassKind::upload};
    phase_pass.writes = {"htsm_phase"};
    phase_pass.data = {"hg-" + number(gg) + "-" + std::to_string(nf),
                       [gg, nf](const ProduceOptions&) {
                           TextureData data;
                           data.size = {nf, 1, 1};
                           std::vector<float> texels(nf);
                           for (int j = 0; j < nf; ++j)
                               texels[j] = float(phase(gg, 2.0 * j / (nf - 1) - 1.0));
                           data.levels = {texels};
                           return data;
                       }};
    plan.add(phase_pass);
}

// The light view (Sec. 4.3, Fig. 4.2): transmitted irradiance and texture coordinate
// with coverage in alpha; its depth is the shadow map of the surface terms.
void add_light_view(PlanBuilder& plan, const FrameInputs& f) {
    const LightView& light = f.light;
    Pass lv{"light_view",
            f.transport ? "mesh from the key light: E (1 - F), texcoord, coverage"
                        : "mesh from the key light: depth for the surface shadow",
            PassKind::draw_mesh,
            {f.mesh_vert, "techniques/htsm/shaders/light_view.frag", {}}};
    lv.uniforms = mesh_transform_uniforms(light.view, light.projection);
    if (f.transport) {
        lv.shader.defines.push_back("WITH_TRANSPORT");
        lv.writes = {"htsm_irradiance", "htsm_texcoord"};
        if (f.full) {
            lv.shader.defines.push_back("WITH_NORMAL");
            lv.writes.push_back("htsm_normal");
        }
        lv.uniforms.push_back({"u_to_light", light.direction});
        lv.uniforms.push_back({"u_light_diffuse", f.scene.light.diffuse});
        lv.uniforms.push_back({"u_eta", float(f.p.ior)});
        lv.uniforms.insert(lv.uniforms.end(), f.box.begin(), f.box.end());
    }
    lv.writes.push_back("light_depth");
    plan.add(lv);
}

void add_light_view_mips(PlanBuilder& plan) {
    for (const char* name : {"htsm_irradiance", "htsm_texcoord"}) {
        Pass m{std::string(name).substr(5) + "_mips",
               std::string("box-filtered mips of ") + name + " (Sec. 4.3.1)",
               PassKind::build_mips};
        m.writes = {name};
        plan.add(m);
    }
}

// The purpose names what was pruned.
std::string pruned_note(const FrameInputs& f) {
    std::string pruned;
    const auto prune = [&](bool kept, const char* what) {
        if (!kept) pruned += (pruned.empty() ? "; pruned: " : ", ") + std::string(what);
    };
    prune(f.transport, "transport passes (Tc = 0 or Id = 0)");
    prune(!f.transport || f.march,
          "volume and march (constant density: tau = (1 + kappa rho0) D)");
    prune(!f.transport || f.table, "phase table (g = 0: isotropic)");
    prune(!f.transport || f.mips, "mips (every lod is 0)");
    prune(f.surface, "surface terms and shadow (wd Kd Id = 0 and ks Is = 0)");
    return pruned;
}

// The shade pass's transport inputs: the light view, the pattern and the density.
void add_transport_inputs(Pass& shade, std::vector<Uniform>& u, const FrameInputs& f,
                          const Sampling& clamp_linear) {
    const Params& p = f.p;
    const LightView& light = f.light;
    shade.shader.defines.push_back("WITH_TRANSPORT");
    shade.shader.defines.push_back("HTSM_SAMPLES " + std::to_string(p.samples));
    const Sampling light_read{TexelFilter::linear,
                              f.mips ? MipFilter::linear : MipFilter::none,
                              Wrap::clamp_to_border, glm::vec4(0.0f)};
    shade.reads.push_back({"htsm_irradiance", "", light_read});
    shade.reads.push_back({"htsm_texcoord", "", light_read});
    u.insert(u.end(), f.box.begin(), f.box.end());
    u.push_back({"u_inv_phi", float(1.0 / f.g.phi)});
    u.push_back({"u_light_centre", light.centre});
    u.push_back({"u_light_right", light.right});
    u.push_back({"u_light_up", light.up});
    u.push_back({"u_to_light", light.direction});
    u.push_back({"u_plane_size", 2.0f * light.radius});
    u.push_back({"u_eps_d", float(2.0 * f.g.texel)});
    u.push_back({"u_transport_colour", glm::vec3(p.transport_colour)});
    u.push_back({"u_transport_distance", float(p.transport_distance)});
    u.push_back({"u_kappa", float(p.density_scale)});
    const std::vector<PatternSample>& samples = f.samples;
    for (std::size_t i = 0; i < samples.size(); ++i)
        u.push_back({"u_pattern[" + std::to_string(i) + "]",
                     glm::vec4(float(samples[i].offset.x), float(samples[i].offset.y),
                               float(samples[i].lod), 0.0f)});
    if (f.march) {
        shade.shader.defines.push_back("DENSITY_VOLUME");
        shade.shader.defines.push_back("HTSM_STEPS " + std::to_string(p.steps));
        shade.reads.push_back({"htsm_density", "", clamp_linear});
    } else {
        u.push_back({"u_rho0", float(constant_density(f.scene))});
    }
    if (f.table) {
        shade.shader.defines.push_back("WITH_PHASE");
        shade.reads.push_back({"htsm_phase", "", clamp_linear});
        u.push_back({"u_phase_size", float(p.phase_table_size)});
    }
}

// The shade pass's surface inputs: the shadow map and the diffuse and specular terms.
void add_surface_inputs(Pass& shade, std::vector<Uniform>& u, const FrameInputs& f) {
    const Params& p = f.p;
    const Scene& scene = f.scene;
    shade.shader.defines.push_back("WITH_SURFACE");
    shade.reads.push_back({"light_depth", "", {TexelFilter::nearest}});
    u.push_back({"u_light_view_projection", f.light.view_projection});
    u.push_back({"u_diffuse_colour",
                 glm::vec3(p.diffuse * p.albedo * glm::dvec3(scene.light.diffuse))});
    u.push_back({"u_specular", glm::vec3(float(p.specular) * scene.light.specular)});
    u.push_back({"u_shininess", float(p.shininess)});
    u.push_back({"u_shadow_offset", float(1.5 * f.g.texel)});
    u.push_back({"u_depth_bias", 0.5f / float(f.wl)});
}

// Table 4.1 with the README's decisions.
void add_shade(PlanBuilder& plan, const FrameInputs& f, SurfaceShading shading) {
    const Scene& scene = f.scene;
    const Params& p = f.p;
    Pass shade{"shade",
               "L = Tc/n sum E w(D + alpha) f + shadowed diffuse + specular, n = " +
                   std::to_string(p.samples) + ", S = " + std::to_string(p.steps) +
                   pruned_note(f),
               PassKind::draw_mesh,
               {f.mesh_vert, "techniques/htsm/shaders/shade.frag", {}}};
    const glm::mat4 view = scene.camera.view();
    const std::vector<Uniform> camera =
        mesh_transform_uniforms(view, scene.camera.projection());
    std::vector<Uniform> u = camera;
    u.push_back({"u_light_direction", scene.light.direction});
    u.push_back({"u_background", scene.background});
    const Sampling clamp_linear{TexelFilter::linear, MipFilter::none,
                                Wrap::clamp_to_edge};
    if (f.transport) add_transport_inputs(shade, u, f, clamp_linear);
    if (f.surface) add_surface_inputs(shade, u, f);
    shade.uniforms = u;
    shade.writes = {"colour", "shade_depth"};
    if (shading == SurfaceShading::deferred)
        shade_deferred(plan, shade, camera, /*eye_normal=*/f.surface,
                       /*ambient_occlusion=*/false);
    shade.clear_colour = glm::vec4(scene.background, 0.0f);
    plan.add(shade);
}

}  // namespace

void add_passes(const Scene& scene, PlanBuilder& plan, SurfaceShading shading) {
    const FrameInputs f(scene, plan.full());
    create_resources(plan, f);
    if (f.march) add_density_volume(plan, f);
    if (f.table) add_phase_table(plan, f);
    if (f.transport || f.surface) add_light_view(plan, f);
    if (f.mips) add_light_view_mips(plan);
    add_shade(plan, f, shading);
    plan.set_output("colour");
}

}  // namespace lucent::htsm
