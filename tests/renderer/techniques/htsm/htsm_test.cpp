// The htsm technique without GL: its plan and prunes, the pattern, and the CPU
// reference against closed forms (a slab of constant density for n = 1, 5, 9, 13, zero
// density, the opaque threshold, the lit face, a sphere's chord) and its own error.
#include "renderer/techniques/htsm/htsm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "renderer/core/technique.h"
#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/registry.h"
#include "tests/renderer/techniques/dipole/test_meshes.h"
#include "tests/support/scene_for_test.h"

namespace lucent::htsm {
namespace {

using test::find_pass;
using test::has_define;

Scene sphere_scene(std::vector<KnobAssignment> settings, int size = 32) {
    return test::scene_for("htsm", std::move(settings), "sphere:2k", size);
}

// The slab of htsm.md section 4: a 1 x 1 x 0.1 box, light along +z behind it, camera
// at -z looking at the unlit face (or at +z at the lit one).
Scene slab_scene(std::vector<KnobAssignment> settings, bool lit_side = false,
                 int size = 32) {
    auto mesh = std::make_shared<const Mesh>(dipole::test::box({1.0f, 1.0f, 0.1f}));
    const Technique& t = find_technique("htsm");
    settings.insert(settings.begin(), {"light_direction", lit_side ? "0,0,1" : "0,0,-1"});
    const KnobValues values = resolve_knob_values(knobs_for(t), settings);
    return make_scene(mesh, t, values, size, size,
                      lit_side ? glm::vec3(0, 0, 1) : glm::vec3(0, 0, -1));
}

// L / Tc on the unlit face of the slab, from the note's closed form (independent of the
// technique's code: the pattern is rebuilt here from its definition).
double slab_closed_form(int n, double kappa_rho0, double g = 0.5, double td = 0.25,
                        double eta = 1.3, double r1_frac = 0.02, double h = 0.1) {
    const double phi = 2.0 * std::sqrt(0.5 + 0.25 * h * h);
    const double f0 = std::pow((eta - 1) / (eta + 1), 2);
    const double e = 1.0 - f0;
    const auto hg = [&](double mu) {
        return g == 0 ? 1.0 : std::pow((1 - g) * (1 - g) / (1 + g * g - 2 * g * mu), 1.5);
    };
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const int k = i == 0 ? 0 : (i - 1) / 4 + 1;
        const double rho = k == 0 ? 0.0 : r1_frac * phi * std::ldexp(1.0, k - 1);
        const double len = std::sqrt(rho * rho + h * h);
        const double w = std::max(0.0, 2.0 - (1.0 + kappa_rho0) * (len / phi) / td);
        sum += w * hg(h / len);
    }
    return e * sum / n;
}

// The mean of the centre 6 x 6 pixels (all well inside the slab's edges).
glm::dvec3 centre_mean(const Image& image) {
    glm::dvec3 sum(0.0);
    const int c = image.width / 2;
    for (int y = c - 3; y < c + 3; ++y)
        for (int x = c - 3; x < c + 3; ++x) sum += glm::dvec3(image.at(x, y));
    return sum / 36.0;
}

ReferenceQuality quick() { return {2, 64}; }
// For the slab's tight gates: a box mean of the light image's piecewise-constant texels
// misses the mean of a linear texcoord by at most delta^2 / (8 w) (delta the fine texel,
// w the footprint), 2.4e-7 object units for F = 4 at W_L = 256 on ring 1.
ReferenceQuality exact_footprints() { return {4, 64}; }

TEST(HtsmPlan, IsRegisteredWithItsKnobs) {
    const Technique& t = find_technique("htsm");
    for (const char* name :
         {"rays", "steps", "light_map_size", "density", "density_resolution",
          "density_contrast", "density_scale", "phase_table_size", "transport_colour",
          "transport_distance", "phase_g", "ior"})
        EXPECT_NE(find_knob(t.knobs(), name), nullptr) << name;
    EXPECT_THROW(parse_knob_value(*find_knob(t.knobs(), "rays"), "7"), KnobError);
    EXPECT_THROW(parse_knob_value(*find_knob(t.knobs(), "phase_g"), "0.9"), KnobError);
    try {
        parse_knob_value(*find_knob(t.knobs(), "density"), "marbel");
        FAIL() << "accepted a bad spec";
    } catch (const KnobError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("density: 'marbel'", 0), 0u) << e.what();
    }
}

TEST(HtsmPlan, DefaultPlanMarchesAVolume) {
    const FramePlan plan = make_frame_plan(sphere_scene({}), find_technique("htsm"));
    for (const char* name : {"density_volume", "phase_table", "light_view",
                             "irradiance_mips", "texcoord_mips", "shade"})
        EXPECT_NE(find_pass(plan, name), nullptr) << name;
    const Pass* shade = find_pass(plan, "shade");
    EXPECT_TRUE(has_define(shade, "DENSITY_VOLUME"));
    EXPECT_TRUE(has_define(shade, "HTSM_SAMPLES 5"));
    EXPECT_TRUE(has_define(shade, "HTSM_STEPS 5"));
    EXPECT_TRUE(has_define(shade, "WITH_PHASE"));
    const ResourceDesc* volume = plan.resource("htsm_density");
    ASSERT_NE(volume, nullptr);
    EXPECT_EQ(volume->shape, ResourceShape::fixed_3d);
    EXPECT_EQ(volume->size, glm::ivec3(64));
    EXPECT_EQ(plan.resource("htsm_normal"), nullptr);  // stored by nothing that reads it
}

TEST(HtsmPlan, PrunesAreNamedAndCostNothing) {
    const Technique& t = find_technique("htsm");
    // A constant volume: closed form along the ray, no upload, no 3-D texture.
    FramePlan plan =
        make_frame_plan(sphere_scene({{"density", "constant:value=0.3"}}), t);
    EXPECT_EQ(find_pass(plan, "density_volume"), nullptr);
    EXPECT_EQ(plan.resource("htsm_density"), nullptr);
    EXPECT_FALSE(has_define(find_pass(plan, "shade"), "DENSITY_VOLUME"));
    EXPECT_NE(plan.explain().find("pruned: volume and march"), std::string::npos);
    // Contrast 0 and kappa = 0 are constant too.
    plan = make_frame_plan(sphere_scene({{"density_contrast", "0"}}), t);
    EXPECT_EQ(find_pass(plan, "density_volume"), nullptr);
    plan = make_frame_plan(sphere_scene({{"density_scale", "0"}}), t);
    EXPECT_EQ(find_pass(plan, "density_volume"), nullptr);
    // Tc = 0: the light view only draws depth for the shadow.
    plan = make_frame_plan(sphere_scene({{"transport_colour", "0"}}), t);
    for (const char* name : {"density_volume", "phase_table", "irradiance_mips"})
        EXPECT_EQ(find_pass(plan, name), nullptr) << name;
    ASSERT_NE(find_pass(plan, "light_view"), nullptr);
    EXPECT_EQ(find_pass(plan, "light_view")->writes,
              std::vector<std::string>{"light_depth"});
    EXPECT_NE(plan.explain().find("pruned: transport passes"), std::string::npos);
    // ... and with no surface terms either, no light view at all.
    plan = make_frame_plan(
        sphere_scene({{"transport_colour", "0"}, {"diffuse", "0"}, {"specular", "0"}}),
        t);
    EXPECT_EQ(find_pass(plan, "light_view"), nullptr);
    // Isotropic phase: no table. n = 1: no mips.
    plan = make_frame_plan(sphere_scene({{"phase_g", "0"}, {"rays", "1"}}), t);
    EXPECT_EQ(find_pass(plan, "phase_table"), nullptr);
    EXPECT_EQ(find_pass(plan, "irradiance_mips"), nullptr);
    EXPECT_EQ(plan.resource("htsm_texcoord")->levels, 1);
    EXPECT_NE(plan.explain().find("phase table (g = 0"), std::string::npos);
    // Full mode keeps everything, the normal image included.
    plan = make_frame_plan(
        sphere_scene({{"density", "constant"}, {"phase_g", "0"}, {"rays", "1"}}), t,
        PlanMode::full);
    EXPECT_TRUE(plan.culled.empty());
    EXPECT_NE(find_pass(plan, "phase_table"), nullptr);
    EXPECT_NE(find_pass(plan, "irradiance_mips"), nullptr);
    EXPECT_NE(find_pass(plan, "density_volume"), nullptr);
    EXPECT_NE(plan.resource("htsm_normal"), nullptr);
}

TEST(HtsmModel, PatternRingsDoubleAndLodsFollowTheFootprint) {
    const Scene scene = sphere_scene({{"rays", "13"}});
    const Params p = params(scene);
    const Geometry g = geometry(scene, p);
    const auto samples = pattern(p, g);
    ASSERT_EQ(samples.size(), 13u);
    EXPECT_EQ(samples[0].lod, 0.0);
    for (int k = 1; k <= 3; ++k)
        for (int j = 0; j < 4; ++j) {
            const auto& s = samples[1 + 4 * (k - 1) + j];
            const double radius = 0.02 * g.phi * std::ldexp(1.0, k - 1);
            EXPECT_NEAR(glm::length(s.offset), radius, 1e-12);
            EXPECT_NEAR(s.lod, std::log2(radius / (g.phi * 1.0 / 256.0 * 1.0)), 1e-3)
                << "lod of ring " << k;  // h_L = 2 R_L / W_L = Phi / 256
        }
    EXPECT_NEAR(samples[1].lod, 2.356, 2e-3);  // htsm.md: lods 2.36/3.36/4.36
}

TEST(HtsmModel, PhaseIsPeakNormalisedHenyeyGreenstein) {
    EXPECT_DOUBLE_EQ(phase(0.5, 1.0), 1.0);
    EXPECT_NEAR(phase(0.5, -1.0), std::pow(0.25 / 2.25, 1.5), 1e-15);
    EXPECT_DOUBLE_EQ(phase(0.0, -0.3), 1.0);
    EXPECT_DOUBLE_EQ(transport_weight(0.0, 0.25), 2.0);
    EXPECT_DOUBLE_EQ(transport_weight(0.25, 0.25), 1.0);
    EXPECT_DOUBLE_EQ(transport_weight(0.75, 0.25), 0.0);  // clamped, never negative
    EXPECT_DOUBLE_EQ(schlick(1.0, 0.5), 0.0);
}

// htsm.md section 4 anchor: L / Tc = 1.41130 (n = 1), 1.18157, 0.97129, 0.76843.
TEST(HtsmReference, SlabOfConstantDensityIsTheClosedForm) {
    EXPECT_NEAR(slab_closed_form(1, 1.0), 1.41130, 1e-5);
    EXPECT_NEAR(slab_closed_form(5, 1.0), 1.18157, 1e-5);
    EXPECT_NEAR(slab_closed_form(9, 1.0), 0.97129, 1e-5);
    EXPECT_NEAR(slab_closed_form(13, 1.0), 0.76843, 1e-5);
    for (int n : {1, 5, 9, 13}) {
        const Scene scene = slab_scene({{"rays", std::to_string(n)},
                                        {"density", "constant:value=0.5"},
                                        {"density_scale", "2"},
                                        {"transport_colour", "1,0.5,0.25"},
                                        {"steps", "1"}});
        const glm::dvec3 l = centre_mean(render_reference(scene, exact_footprints()));
        const double expected = slab_closed_form(n, 1.0);
        EXPECT_NEAR(l.r, expected, 1e-4 * expected) << "n = " << n;
        EXPECT_NEAR(l.g, 0.5 * expected, 1e-4 * expected) << "n = " << n;
        EXPECT_NEAR(l.b, 0.25 * expected, 1e-4 * expected) << "n = " << n;
    }
}

TEST(HtsmReference, ZeroDensityIsPureTransport) {
    const Scene scene = slab_scene({{"rays", "9"}, {"density", "constant:value=0"}});
    const FramePlan plan = make_frame_plan(scene, find_technique("htsm"));
    EXPECT_EQ(find_pass(plan, "density_volume"), nullptr);
    const glm::dvec3 l = centre_mean(render_reference(scene, exact_footprints()));
    const glm::dvec3 tc = params(scene).transport_colour;
    EXPECT_NEAR(l.r, tc.r * slab_closed_form(9, 0.0), 1e-4);
}

TEST(HtsmReference, DensityAboveTheThresholdMakesTheUnlitFaceBlack) {
    // kappa rho0 >= 2 Td Phi / h - 1 = 6.0887 (htsm.md): w clamps to exactly 0.
    const Scene above = slab_scene({{"rays", "1"},
                                    {"density", "constant:value=1"},
                                    {"density_scale", "6.1"},
                                    {"steps", "3"}});
    EXPECT_EQ(centre_mean(render_reference(above, quick())), glm::dvec3(0.0));
    const Scene below = slab_scene(
        {{"rays", "1"}, {"density", "constant:value=1"}, {"density_scale", "6.0"}});
    const double expected = slab_closed_form(1, 6.0);
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(centre_mean(render_reference(below, quick())).r,
                params(below).transport_colour.r * expected, 1e-4);
}

TEST(HtsmReference, LitFaceKeepsItsCentreTerm) {
    // Lit face, camera on the light's side, no surface terms: the centre ray has d = 0,
    // weight 2 and mu = -N.L = -1; each ring ray runs along the face (mu = 0) with
    // D = rho / Phi.
    const double g = 0.5, kr = 3.0, phi = 2.0 * std::sqrt(0.5 + 0.0025);
    const Scene scene = slab_scene({{"rays", "5"},
                                    {"density", "constant:value=1"},
                                    {"density_scale", std::to_string(kr)},
                                    {"diffuse", "0"},
                                    {"specular", "0"}},
                                   true);
    const double e = 1.0 - std::pow(0.3 / 2.3, 2);
    const double rho = 0.02 * phi;
    const double ring = std::max(0.0, 2.0 - (1 + kr) * (rho / phi) / 0.25) *
                        std::pow((1 - g) * (1 - g) / (1 + g * g), 1.5);
    const double expected = e * (2.0 * std::pow(0.25 / 2.25, 1.5) + 4.0 * ring) / 5.0;
    const glm::dvec3 l = centre_mean(render_reference(scene, quick()));
    EXPECT_NEAR(l.r, params(scene).transport_colour.r * expected, 2e-4);
}

TEST(HtsmReference, SphereChordIsTheClosedForm) {
    // Light from behind, n = 1, homogeneous: END is the far end of the chord along l,
    // D = 2 sqrt(r^2 - b^2) / Phi, E = (1 - F(c)) c with c = sqrt(1 - (b/r)^2), mu = c.
    const Scene scene = test::scene_for("htsm",
                                        {{"rays", "1"},
                                         {"density", "constant:value=0.5"},
                                         {"density_scale", "1"},
                                         {"light_direction", "0,0,-1"},
                                         {"transport_distance", "1"},
                                         {"phase_g", "0.3"}},
                                        "sphere:20k", 48);
    const Image image = render_reference(scene, quick());
    const Params p = params(scene);
    const double r = scene.bounds.radius;
    const PixelRays rays(scene.camera, 48, 48);
    const RayCaster caster(*scene.mesh);
    int checked = 0;
    double worst = 0.0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) {
            const auto hit =
                caster.first_hit(glm::vec3(rays.eye()), glm::vec3(rays.direction(x, y)));
            if (!hit) continue;
            const glm::dvec3 point =
                rays.eye() + double(hit->distance) * rays.direction(x, y);
            const glm::dvec3 rel = point - glm::dvec3(scene.bounds.centre);
            const glm::dvec3 l =
                glm::normalize(glm::dvec3(light_direction_object(scene)));
            const double b = glm::length(rel - glm::dot(rel, l) * l);
            if (b > 0.8 * r) continue;  // the silhouette band
            const double c = std::sqrt(1.0 - (b / r) * (b / r));
            const double d = 2.0 * r * c / (2.0 * r);
            const double expected = p.transport_colour.r * (1.0 - schlick(1.3, c)) * c *
                                    transport_weight(1.5 * d, 1.0) * phase(0.3, c);
            worst = std::max(worst, std::abs(image.at(x, y).r - expected) / expected);
            ++checked;
        }
    std::printf("sphere chord: %d pixels, worst relative error %.3g\n", checked, worst);
    EXPECT_GT(checked, 500);
    EXPECT_LT(worst, 0.02);  // a 20k-face sphere's facets, not the model
}

TEST(HtsmReference, SphereImageIsSymmetric) {
    // Light from behind along the view axis: the image of a homogeneous sphere is
    // mirror-symmetric left-right and top-bottom (to the mesh's symmetry).
    const Scene scene = sphere_scene({{"rays", "13"},
                                      {"density", "constant:value=0.5"},
                                      {"transport_distance", "1"},
                                      {"light_direction", "0,0,-1"}},
                                     32);
    const Image image = render_reference(scene, quick());
    double worst = 0.0, peak = 0.0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            const glm::vec4 a = image.at(x, y), b = image.at(31 - x, y),
                            c = image.at(x, 31 - y);
            if (a.a == 0 || b.a == 0 || c.a == 0) continue;
            worst = std::max(
                {worst, double(std::abs(a.r - b.r)), double(std::abs(a.r - c.r))});
            peak = std::max(peak, double(a.r));
        }
    EXPECT_GT(peak, 0.1);
    EXPECT_LT(worst, 0.03 * peak);
}

TEST(HtsmReference, HardCasesStayFinite) {
    const std::vector<std::vector<KnobAssignment>> cases = {
        {{"density_scale", "1000"}, {"density", "constant:value=1"}},
        {{"density_scale", "0"}},
        {{"light_direction", "1,0,0.0001"}},             // grazing
        {{"light_direction", "0,1,0"}},                  // up-vector fallback
        {{"pattern_radius", "0.5"}, {"rays", "13"}},     // samples outside the view
        {{"density", "cube:size=0.2"}, {"steps", "1"}},  // volume feature small, S = 1
        {{"transport_distance", "0.001"}},
        {{"ior", "1"}, {"phase_g", "0.8"}},
    };
    for (const auto& settings : cases) {
        const Image image = render_reference(sphere_scene(settings, 16), quick());
        EXPECT_EQ(count_non_finite_pixels(image), 0u) << settings.front().key;
        for (float v : image.rgba) EXPECT_GE(v, 0.0f);
    }
}

TEST(HtsmReference, ReportsItsOwnError) {
    ReferenceError error;
    const Image fine = render_reference_with_error(sphere_scene({{"rays", "5"}}, 24),
                                                   ReferenceQuality{4, 256}, error);
    std::printf("reference self-estimate (F 4 vs 2, S 256 vs 128): rms %.3g max %.3g\n",
                error.rms, error.max);
    EXPECT_LT(error.rms, 0.01);
    EXPECT_EQ(count_non_finite_pixels(fine), 0u);
}

}  // namespace
}  // namespace lucent::htsm
