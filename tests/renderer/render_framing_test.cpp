// Framing of portrait and landscape images: the camera fits the bounding sphere across
// the image's shorter side, so every technique (GL and CPU reference) shows a unit
// sphere as a circle of the analytic radius, centred, with no object pixel on the edge
// columns or rows, as `lucent render --size 64x128` and `--size 128x64` would.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "tests/support/gl_test_fixture.h"

namespace lucent {
namespace {

class RenderFraming : public test::HeadlessGlTest {};

// Covered pixels (alpha = coverage > 1/2) of an image, overall and per edge and axis.
struct Coverage {
    std::size_t pixels = 0;
    std::size_t on_edges = 0;    // in the first or last column or row
    int centre_row_span = 0;     // covered pixels in the middle row
    int centre_column_span = 0;  // covered pixels in the middle column
};

Coverage coverage_of(const Image& image) {
    Coverage c;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            if (!(image.at(x, y).a > 0.5f)) continue;
            ++c.pixels;
            if (x == 0 || y == 0 || x == image.width - 1 || y == image.height - 1)
                ++c.on_edges;
            if (y == image.height / 2) ++c.centre_row_span;
            if (x == image.width / 2) ++c.centre_column_span;
        }
    return c;
}

// A sphere of radius R seen from distance D subtends asin(R / D); on an image whose
// shorter side has S pixels spanning the field of view `fov`, its silhouette is a circle
// of radius S/2 * tan(asin(R / D)) / tan(fov / 2) pixels.
double analytic_radius_pixels(const Scene& scene, double sphere_radius,
                              double fov_degrees) {
    const double distance = glm::length(scene.camera.eye - scene.bounds.centre);
    const double shorter = std::min(scene.width, scene.height);
    return shorter / 2.0 * std::tan(std::asin(sphere_radius / distance)) /
           std::tan(glm::radians(fov_degrees) / 2.0);
}

TEST_F(RenderFraming, PortraitAndLandscapeShowTheWholeSphereAtItsAnalyticRadius) {
    gl::FrameExecutor executor;
    const double fov = 64.0;  // a little wider than the fit: 2 px of margin at 64 px
    for (const Technique* technique : all_techniques()) {
        // thick_texture draws sheets with UVs, not spheres (its framing is the same
        // camera; its tests check GL against the reference at the image centre).
        if (technique->name() == "thick_texture") continue;
        for (const auto& [width, height] : {std::pair{64, 128}, std::pair{128, 64}}) {
            RenderRequest request;
            request.mesh = "sphere:20k";  // the unit sphere
            request.technique = std::string(technique->name());
            request.settings = {{"fov_y", std::to_string(fov)}};
            if (find_knob(technique->knobs(), "ao_rays"))  // htsm has no AO
                request.settings.push_back({"ao_rays", "8"});
            request.width = width;
            request.height = height;
            const Scene scene = build_scene(request);
            const double radius = analytic_radius_pixels(scene, 1.0, fov);
            ASSERT_LT(radius, std::min(width, height) / 2.0 - 1.5);
            const std::string label = request.technique + " " + std::to_string(width) +
                                      "x" + std::to_string(height);
            for (const auto& [path, image] :
                 {std::pair{"GL", render_image(executor, scene)},
                  std::pair{"CPU", technique->render_reference(scene)}}) {
                const Coverage c = coverage_of(image);
                EXPECT_EQ(c.on_edges, 0u) << label << " " << path;
                // Area pi r^2 and both diameters: a circle, not an ellipse or a crop.
                EXPECT_NEAR(std::sqrt(double(c.pixels) / M_PI), radius, 0.35)
                    << label << " " << path;
                EXPECT_NEAR(c.centre_row_span, 2.0 * radius, 1.5) << label << " " << path;
                EXPECT_NEAR(c.centre_column_span, 2.0 * radius, 1.5)
                    << label << " " << path;
            }
        }
    }
}

// At the default fov (60: the bounding sphere fits exactly) the thesis's knot stays
// inside a portrait and a landscape frame too.
TEST_F(RenderFraming, DefaultKnotLeavesTheEdgesOfPortraitAndLandscapeImagesEmpty) {
    gl::FrameExecutor executor;
    for (const auto& [width, height] : {std::pair{64, 128}, std::pair{128, 64}}) {
        RenderRequest request;
        request.settings = {{"ao_rays", "8"}};
        request.width = width;
        request.height = height;
        const Coverage c = coverage_of(render_image(executor, build_scene(request)));
        EXPECT_EQ(c.on_edges, 0u) << width << "x" << height;
        EXPECT_GT(c.pixels, std::size_t(width * height) / 20) << width << "x" << height;
    }
}

}  // namespace
}  // namespace lucent
