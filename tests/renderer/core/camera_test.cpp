// fit_camera against the thesis's rule (Eq. 3.4): eye one diameter from the centre,
// near/far planes touching the bounding sphere; projection's depth mapping checked on
// points placed at the planes.
#include "renderer/core/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace lucent {
namespace {

glm::vec3 to_ndc(const Camera& camera, glm::vec3 world) {
    const glm::vec4 clip = camera.projection() * camera.view() * glm::vec4(world, 1.0f);
    return glm::vec3(clip) / clip.w;
}

TEST(Camera, EyeSitsOneDiameterFromTheCentreAlongTheViewDirection) {
    const BoundingSphere sphere{{1.0f, -2.0f, 3.0f}, 0.75f};
    const Camera camera = fit_camera(sphere, 40.0f, 1.5f, {0.0f, 0.0f, 5.0f});
    EXPECT_NEAR(glm::length(camera.eye - sphere.centre), 1.5f, 1e-6f);
    EXPECT_NEAR(camera.eye.z - sphere.centre.z, 1.5f, 1e-6f);
    EXPECT_EQ(camera.target, sphere.centre);
    EXPECT_FLOAT_EQ(camera.fov_y_degrees, 40.0f);
    EXPECT_FLOAT_EQ(camera.aspect, 1.5f);
    // The planes hug the sphere: nearest and farthest points of it along the axis.
    EXPECT_NEAR(camera.near_plane, 0.75f, 1e-6f);
    EXPECT_NEAR(camera.far_plane, 2.25f, 1e-6f);
}

TEST(Camera, ProjectionMapsTheSpheresNearAndFarPointsToMinusOneAndOne) {
    const BoundingSphere sphere{{0.5f, 0.25f, -1.0f}, 2.0f};
    const glm::vec3 direction = glm::normalize(glm::vec3(1.0f, 2.0f, -0.5f));
    const Camera camera = fit_camera(sphere, 60.0f, 1.0f, direction);
    const glm::vec3 nearest = sphere.centre + direction * sphere.radius;
    const glm::vec3 farthest = sphere.centre - direction * sphere.radius;
    EXPECT_NEAR(to_ndc(camera, nearest).z, -1.0f, 1e-5f);
    EXPECT_NEAR(to_ndc(camera, farthest).z, 1.0f, 1e-4f);
    // The centre projects to the middle of the image.
    const glm::vec3 centre = to_ndc(camera, sphere.centre);
    EXPECT_NEAR(centre.x, 0.0f, 1e-5f);
    EXPECT_NEAR(centre.y, 0.0f, 1e-5f);
}

TEST(Camera, ViewLooksDownMinusZAndProjectionUsesTheFieldOfView) {
    const Camera camera = fit_camera({{0.0f, 0.0f, 0.0f}, 1.0f}, 90.0f, 2.0f);
    const glm::vec4 eye_space = camera.view() * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    EXPECT_NEAR(eye_space.z, -2.0f, 1e-6f);
    // With fov_y 90 degrees, a point at height = depth lands on the top edge (ndc y = 1);
    // with aspect 2, a point at x = 2 * depth lands on the right edge.
    EXPECT_NEAR(to_ndc(camera, {0.0f, 2.0f, 0.0f}).y, 1.0f, 1e-5f);
    EXPECT_NEAR(to_ndc(camera, {4.0f, 0.0f, 0.0f}).x, 1.0f, 1e-5f);
}

// The tangent rays from the eye (distance 2 from a unit sphere) touch it at z = 1/2,
// |x| or |y| = sqrt(3)/2, 30 degrees off the axis. With fov 60 across the shorter side
// they land on that side's edges (ndc +-1) and the longer side's ndc is 1/aspect or
// aspect times smaller, in both orientations.
TEST(Camera, FieldOfViewSpansTheShorterSideSoTheSphereFitsBothAxes) {
    const float s = std::sqrt(3.0f) / 2.0f;
    for (const float aspect : {0.5f, 0.25f, 1.0f, 2.0f, 4.0f}) {
        const Camera camera = fit_camera({{0.0f, 0.0f, 0.0f}, 1.0f}, 60.0f, aspect);
        const float x = to_ndc(camera, {s, 0.0f, 0.5f}).x;
        const float y = to_ndc(camera, {0.0f, s, 0.5f}).y;
        EXPECT_NEAR(std::max(x, y), 1.0f, 1e-5f) << "aspect " << aspect;
        EXPECT_NEAR(x, aspect < 1.0f ? 1.0f : 1.0f / aspect, 1e-5f)
            << "aspect " << aspect;
        EXPECT_NEAR(y, aspect < 1.0f ? aspect : 1.0f, 1e-5f) << "aspect " << aspect;
    }
    // Square and landscape images keep the knob as their vertical field of view.
    EXPECT_EQ(fit_camera({{0, 0, 0}, 1.0f}, 60.0f, 1.0f).fov_y_degrees, 60.0f);
    EXPECT_EQ(fit_camera({{0, 0, 0}, 1.0f}, 37.0f, 1.6f).fov_y_degrees, 37.0f);
    // Portrait: tan(fov_y / 2) = tan(30 deg) / aspect.
    EXPECT_NEAR(std::tan(glm::radians(vertical_fov_degrees(60.0f, 0.5f)) / 2.0f),
                2.0f * std::tan(glm::radians(30.0f)), 1e-5f);
    // Even the narrowest image keeps a finite projection below 180 degrees.
    const float narrow = vertical_fov_degrees(170.0f, 1.0f / 16384.0f);
    EXPECT_LT(narrow, 180.0f);
    EXPECT_GT(narrow, 170.0f);
}

TEST(Camera, ViewFromStraightAboveIsStillAValidMatrix) {
    const Camera camera =
        fit_camera({{0.0f, 0.0f, 0.0f}, 1.0f}, 45.0f, 1.0f, {0.0f, 1.0f, 0.0f});
    const glm::mat4 view = camera.view();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) ASSERT_TRUE(std::isfinite(view[c][r]));
    EXPECT_NEAR((view * glm::vec4(0, 0, 0, 1)).z, -2.0f, 1e-6f);
}

TEST(Camera, DegenerateSphereAndDirectionStillGiveAValidFrustum) {
    const Camera camera =
        fit_camera({{0.0f, 0.0f, 0.0f}, 0.0f}, 45.0f, 1.0f, {0.0f, 0.0f, 0.0f});
    EXPECT_GT(camera.near_plane, 0.0f);
    EXPECT_GT(camera.far_plane, camera.near_plane);
    EXPECT_GT(camera.eye.z, 0.0f);  // falls back to +Z
}

}  // namespace
}  // namespace lucent
