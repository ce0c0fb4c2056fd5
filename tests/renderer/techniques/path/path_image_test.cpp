// The path technique's image against closed forms: the white furnace, a clear slab seen
// through (Beer-Lambert and the multiple reflections between Fresnel interfaces), the key
// light's disc converging to a directional light as its radius shrinks (eta = 1), every
// shortcut equal to the full walk within its standard error, hard cases finite, and the
// plan's image (GL upload) equal to the tracer's.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/core/technique.h"
#include "renderer/render.h"
#include "renderer/techniques/path/path.h"
#include "renderer/techniques/registry.h"
#include "tests/renderer/techniques/dipole/test_meshes.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/scene_for_test.h"

namespace lucent::path {
namespace {

Scene sphere(std::vector<KnobAssignment> settings, int size = 12) {
    return test::scene_for("path", std::move(settings), "sphere:2k", size);
}

// A 1 x 1 x 0.1 box seen along -z through its middle, with the environment behind it.
Scene thin_box(std::vector<KnobAssignment> settings, int size = 9) {
    auto mesh = std::make_shared<const Mesh>(dipole::test::box({1.0f, 1.0f, 0.1f}));
    const Technique& t = find_technique("path");
    const KnobValues values = resolve_knob_values(knobs_for(t), settings);
    Scene scene = make_scene(mesh, t, values, size, size);
    t.check_scene(scene);
    return scene;
}

// Object pixels of `image` (alpha 1) and their count.
template <class F>
int for_object_pixels(const Image& image, F&& visit) {
    int count = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            if (image.at(x, y).a == 1.0f) {
                visit(x, y);
                ++count;
            }
    return count;
}

const std::vector<KnobAssignment> kFurnace = {{"light_ambient", "1,1,1"},
                                              {"light_diffuse", "0,0,0"},
                                              {"background", "0,0,0"},
                                              {"material", "custom"},
                                              {"sigma_a", "0,0,0"},
                                              {"sigma_s_prime", "2,1,0.5"},
                                              {"paths", "4"}};

// Without absorption every path leaves the object and sees the uniform environment: each
// sample is exactly 1, whatever the index, the phase function or the density.
TEST(PathImage, WhiteFurnaceIsOneEverywhere) {
    for (const std::vector<KnobAssignment>& extra :
         std::vector<std::vector<KnobAssignment>>{
             {{"eta", "1"}},
             {{"eta", "1.5"}, {"g", "0.8"}},
             {{"eta", "2"}, {"density", "marble"}},
             {{"eta", "1.3"}, {"sigma_s_prime", "0,0,0"}}}) {
        std::vector<KnobAssignment> settings = kFurnace;
        settings.insert(settings.end(), extra.begin(), extra.end());
        const EstimatedImage e = render_path(sphere(settings));
        const int pixels = for_object_pixels(e.mean, [&](int x, int y) {
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(e.mean.at(x, y)[c], 1.0f, 1e-6f) << x << "," << y;
                EXPECT_NEAR(e.standard_error.at(x, y)[c], 0.0f, 1e-6f);
            }
        });
        EXPECT_GT(pixels, 40);
        EXPECT_EQ(e.mean.at(0, 0), glm::vec4(0.0f));  // the background, not covered
    }
}

// Through the middle of a clear slab of thickness d: the environment Ia attenuated by
// exp(-sigma_a d) with an index-matched interface; between Fresnel interfaces at normal
// incidence, R + T of the multiple reflections, r = ((eta-1)/(eta+1))^2, T = exp(-sigma_a
// d): r + (1-r)^2 r T^2 / (1 - r^2 T^2) + (1-r)^2 T / (1 - r^2 T^2).
TEST(PathImage, ClearSlabMatchesBeerLambertAndMultipleReflections) {
    // model_size is the box's diagonal in mm: thickness d = 0.1 / sqrt(2.01) of it.
    const double model_size = 10.0, d = model_size * 0.1 / std::sqrt(2.01);
    const double sigma_a = 0.5;  // mm^-1
    for (const double eta : {1.0, 1.5}) {
        const Scene scene = thin_box({{"light_ambient", "1,1,1"},
                                      {"light_diffuse", "0,0,0"},
                                      {"material", "custom"},
                                      {"sigma_a", "0.5,0.5,0.5"},
                                      {"sigma_s_prime", "0,0,0"},
                                      {"eta", std::to_string(eta)},
                                      {"model_size", std::to_string(model_size)},
                                      {"paths", "4000"}});
        const EstimatedImage e = render_path(scene);
        const double r = std::pow((eta - 1) / (eta + 1), 2), t = std::exp(-sigma_a * d);
        const double expected =
            r + (1 - r) * (1 - r) * (r * t * t + t) / (1 - r * r * t * t);
        const glm::vec4 centre = e.mean.at(4, 4), error = e.standard_error.at(4, 4);
        ASSERT_EQ(centre.a, 1.0f);
        // + 5e-5 relative: each crossing restarts 1e-5 bounding radii off the surface
        // (the walk's spawn offset), which shortens the path inside by about that much.
        EXPECT_LE(std::abs(centre.g - expected), 3.0 * error.g + 5e-5 * expected)
            << "eta " << eta << ": " << centre.g << " +- " << error.g << " vs "
            << expected;
        if (eta == 1.0) {
            EXPECT_EQ(error.g, 0.0f);  // Beer-Lambert weights: no noise
        }
    }
}

// eta = 1: the key light's disc (phase-sampled hits and shadow rays, combined by the
// power heuristic) converges to the directional light (shadow rays only) as the radius
// shrinks.
TEST(PathImage, KeyLightDiscConvergesToTheDirectionalLight) {
    const auto render = [](const std::string& radius) {
        return render_path(sphere({{"light_ambient", "0,0,0"},
                                   {"light_direction", "1,0,0"},
                                   {"material", "custom"},
                                   {"sigma_a", "0.05,0.05,0.05"},
                                   {"sigma_s_prime", "0.4,0.4,0.4"},
                                   {"eta", "1"},
                                   {"light_radius", radius},
                                   {"paths", "64"}},
                                  10));
    };
    const EstimatedImage limit = render("0");
    double previous = INFINITY;
    for (const std::string radius : {"40", "20", "5"}) {
        const EstimatedImage disc = render(radius);
        double difference = 0.0, error = 0.0;
        const int n = for_object_pixels(limit.mean, [&](int x, int y) {
            difference += disc.mean.at(x, y).g - limit.mean.at(x, y).g;
            error += std::pow(disc.standard_error.at(x, y).g, 2) +
                     std::pow(limit.standard_error.at(x, y).g, 2);
        });
        ASSERT_GT(n, 20);
        difference = std::abs(difference / n);
        error = std::sqrt(error) / n;
        EXPECT_LT(difference, previous) << "radius " << radius;
        previous = difference;
        if (radius == "5") {
            EXPECT_LE(difference, 3.0 * error + 1e-4) << difference << " +- " << error;
        }
    }
}

// The key light by shadow rays and phase-sampled hits (combined by the power heuristic)
// against phase-sampled hits alone: two estimators of one image. At eta = 1 the shadow
// rays go straight; at eta = 1.3 through one facet (aimed so that it refracts towards
// the light), which phase sampling alone reaches only by chance.
TEST(PathImage, LightSamplingEqualsPhaseSamplingAlone) {
    for (const char* eta : {"1", "1.3"}) {
        const Scene scene = sphere({{"light_ambient", "0,0,0"},
                                    {"light_direction", "1,0.5,0.3"},
                                    {"material", "custom"},
                                    {"sigma_a", "0.05,0.05,0.05"},
                                    {"sigma_s_prime", "0.4,0.4,0.4"},
                                    {"eta", eta},
                                    {"light_radius", "30"},
                                    {"paths", "256"}},
                                   6);
        const EstimatedImage both = render_path(scene);
        TraceOptions phase_only;
        phase_only.light_sampling = false;
        const EstimatedImage alone = render_path(scene, phase_only);
        double difference = 0.0, variance = 0.0, total = 0.0, both_variance = 0.0;
        const int n = for_object_pixels(both.mean, [&](int x, int y) {
            difference += both.mean.at(x, y).g - alone.mean.at(x, y).g;
            variance += std::pow(both.standard_error.at(x, y).g, 2) +
                        std::pow(alone.standard_error.at(x, y).g, 2);
            both_variance += std::pow(both.standard_error.at(x, y).g, 2);
            total += alone.mean.at(x, y).g;
        });
        ASSERT_GT(n, 10);
        EXPECT_GT(total / n, 0.01) << eta;  // lit
        EXPECT_LE(std::abs(difference), 3.0 * std::sqrt(variance))
            << "eta " << eta << ": " << difference / n << " +- "
            << std::sqrt(variance) / n << " on " << total / n;
        // And light sampling pays: less noise than phase sampling alone.
        EXPECT_LT(both_variance, 0.5 * (variance - both_variance)) << eta;
    }
}

// Each shortcut (no Fresnel at eta = 1, Beer-Lambert without scattering, no lookups in a
// constant density, no walks where a channel has no light) against the full walk.
TEST(PathImage, ShortcutsEqualTheFullWalkWithinTheirErrors) {
    for (const std::vector<KnobAssignment>& settings :
         std::vector<std::vector<KnobAssignment>>{
             {{"eta", "1"}, {"density", "constant:value=0.7"}},
             {{"eta", "1"}, {"sigma_s_prime", "0,0,0"}, {"sigma_a", "0.3,0.2,0.1"}},
             {{"eta", "1.4"},
              {"light_diffuse", "1,0,1"},
              {"light_ambient", "0.5,0,0"}}}) {
        std::vector<KnobAssignment> all = {{"material", "custom"},
                                           {"sigma_a", "0.05,0.1,0.2"},
                                           {"sigma_s_prime", "1,1,1"},
                                           {"paths", "64"},
                                           {"light_radius", "10"}};
        all.insert(all.end(), settings.begin(), settings.end());
        const Scene scene = sphere(all, 8);
        const EstimatedImage pruned = render_path(scene);
        TraceOptions full;
        full.full = true;
        const EstimatedImage reference = render_path(scene, full);
        int far = 0, values = 0;
        for_object_pixels(pruned.mean, [&](int x, int y) {
            for (int c = 0; c < 3; ++c) {
                const double se = std::hypot(pruned.standard_error.at(x, y)[c],
                                             reference.standard_error.at(x, y)[c]);
                const double gap =
                    std::abs(pruned.mean.at(x, y)[c] - reference.mean.at(x, y)[c]);
                far += gap > 3.5 * se + 1e-6;
                ++values;
            }
        });
        EXPECT_LE(far, values / 100 + 1) << far << " of " << values;
    }
}

TEST(PathImage, HardCasesStayFinite) {
    for (const std::vector<KnobAssignment>& settings :
         std::vector<std::vector<KnobAssignment>>{
             {{"material", "marble"}, {"model_size", "1000"}},   // optically very thick
             {{"material", "skimmilk"}, {"model_size", "0.1"}},  // optically very thin
             {{"material", "custom"}, {"sigma_a", "0,0,0"}, {"eta", "2"}},  // albedo 1
             {{"material", "custom"}, {"sigma_s_prime", "0,0,0"}, {"sigma_a", "0,0,0"}},
             {{"light_direction", "0,1,0.001"},
              {"fov_y", "170"}},  // grazing light, wide view
             {{"g", "0.95"}, {"density", "spheres"}},
             {{"g", "-0.95"}, {"light_radius", "0.01"}}}) {
        std::vector<KnobAssignment> all = settings;
        all.push_back({"paths", "2"});
        const EstimatedImage e = render_path(sphere(all, 8));
        for (const float v : e.mean.rgba) ASSERT_TRUE(std::isfinite(v));
        for (const float v : e.standard_error.rgba) ASSERT_TRUE(std::isfinite(v));
    }
}

TEST(PathImage, IsTheSameForASeedAndDiffersForAnother) {
    const std::vector<KnobAssignment> settings = {{"paths", "3"}, {"material", "marble"}};
    const EstimatedImage a = render_path(sphere(settings)),
                         b = render_path(sphere(settings));
    EXPECT_EQ(a.mean.rgba, b.mean.rgba);
    std::vector<KnobAssignment> other = settings;
    other.push_back({"seed", "7"});
    EXPECT_NE(render_path(sphere(other)).mean.rgba, a.mean.rgba);
}

// A time budget stops after the pass of paths that exceeds it (at least one), and the
// summary says how many of the asked-for paths were traced.
TEST(PathImage, ATimeBudgetStopsEarlyAndSaysSo) {
    const Scene scene = sphere({{"material", "marble"},
                                {"model_size", "100"},
                                {"paths", "100000"},
                                {"time_budget", "0.05"}},
                               16);
    TraceStatistics statistics;
    const EstimatedImage e = render_path(scene, {}, &statistics);
    EXPECT_GE(statistics.paths_done, 1);
    EXPECT_LT(statistics.paths_done, 100000);
    EXPECT_NE(e.summary.find(std::to_string(statistics.paths_done) + " of 100000"),
              std::string::npos)
        << e.summary;
    for (const float v : e.mean.rgba) ASSERT_TRUE(std::isfinite(v));
}

TEST(PathImage, RefusesAnOpenMeshAndAnUnreachableDirectionalLight) {
    try {
        test::scene_for("path", {}, "square", 8);
        FAIL() << "an open mesh was accepted";
    } catch (const MeshError& e) {
        EXPECT_NE(std::string(e.what()).find("closed"), std::string::npos) << e.what();
    }
    EXPECT_THROW(sphere({{"light_radius", "0"}}), KnobError);  // skin1: eta 1.3
    EXPECT_NO_THROW(
        sphere({{"light_radius", "0"}, {"material", "custom"}, {"eta", "1"}}));
}

TEST(PathImage, ExplainNamesEveryShortcut) {
    const Scene scene = sphere({{"material", "custom"},
                                {"eta", "1"},
                                {"sigma_s_prime", "0,0,0"},
                                {"light_diffuse", "0,0,0"}});
    const std::string pruned = make_frame_plan(scene, find_technique("path")).explain();
    for (const char* phrase :
         {"no Fresnel", "no collisions", "no density lookups", "key light off"})
        EXPECT_NE(pruned.find(phrase), std::string::npos) << phrase << " in\n" << pruned;
    const std::string full =
        make_frame_plan(scene, find_technique("path"), PlanMode::full).explain();
    EXPECT_NE(full.find("no shortcuts"), std::string::npos) << full;
}

// The image `lucent render` writes goes through the plan's upload: the same as the
// tracer's, row for row.
class PathImageGl : public test::HeadlessGlTest {};

TEST_F(PathImageGl, ThePlansImageIsTheTracers) {
    gl::FrameExecutor executor;
    const Scene scene = sphere({{"paths", "2"}}, 7);
    const Image through_gl = render_image(executor, scene);
    const Image traced = render_path(scene).mean;
    EXPECT_EQ(through_gl.rgba, traced.rgba);
}

}  // namespace
}  // namespace lucent::path
