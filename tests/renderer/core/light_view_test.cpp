// The light's orthographic view, checked against where it must put the bounding sphere:
// the sphere's extreme points along the image axes land on the clip-space edges, its
// nearest and farthest points along the light on the depth range's ends.
#include "renderer/core/light_view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "renderer/core/scene.h"
#include "renderer/core/technique.h"
#include "renderer/techniques/registry.h"

namespace lucent {
namespace {

glm::vec3 to_ndc(const LightView& view, glm::vec3 p) {
    const glm::vec4 clip = view.view_projection * glm::vec4(p, 1.0f);
    return glm::vec3(clip) / clip.w;
}

void expect_near(glm::vec3 actual, glm::vec3 expected, float tolerance,
                 const char* what) {
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(actual[k], expected[k], tolerance) << what << " axis " << k;
}

TEST(LightView, FitsTheBoundingSphereForManyDirections) {
    const BoundingSphere sphere{{0.5f, -2.0f, 3.0f}, 1.75f};
    // Axis-aligned lights, the y axis (where the up hint switches), and oblique ones.
    for (const glm::vec3 to_light :
         {glm::vec3(0, 0, 1), glm::vec3(0, 0, -3), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0),
          glm::vec3(0, -2, 0), glm::vec3(0.001f, 1, 0), glm::vec3(1, 2, 3),
          glm::vec3(-0.3f, 0.2f, -0.9f)}) {
        const LightView view = fit_light_view(sphere, to_light);
        const glm::vec3 d = glm::normalize(to_light);
        expect_near(view.direction, d, 1e-6f, "direction");
        // (right, up, direction) is a right-handed orthonormal frame.
        EXPECT_NEAR(glm::length(view.right), 1.0f, 1e-6f);
        EXPECT_NEAR(glm::length(view.up), 1.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(view.right, view.up), 0.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(view.right, d), 0.0f, 1e-6f);
        expect_near(glm::cross(view.right, view.up), d, 1e-5f, "right x up");
        const float r = sphere.radius;
        const glm::vec3 c = sphere.centre;
        expect_near(to_ndc(view, c), {0, 0, 0}, 1e-5f, "centre");
        expect_near(to_ndc(view, c + r * view.right), {1, 0, 0}, 1e-5f, "+right");
        expect_near(to_ndc(view, c - r * view.right), {-1, 0, 0}, 1e-5f, "-right");
        expect_near(to_ndc(view, c + r * view.up), {0, 1, 0}, 1e-5f, "+up");
        expect_near(to_ndc(view, c - r * view.up), {0, -1, 0}, 1e-5f, "-up");
        // Nearest to the light -> z_ndc -1 (window depth 0), farthest -> +1.
        expect_near(to_ndc(view, c + r * d), {0, 0, -1}, 1e-5f, "towards the light");
        expect_near(to_ndc(view, c - r * d), {0, 0, 1}, 1e-5f, "away from the light");
        // Orthographic: w stays 1 and a shift along the light changes depth only, by
        // 1 / R in z_ndc per unit length.
        const glm::vec4 clip = view.view_projection * glm::vec4(c + 0.3f * view.up, 1.0f);
        EXPECT_FLOAT_EQ(clip.w, 1.0f);
        const glm::vec3 shifted = to_ndc(view, c + 0.3f * view.up - 0.5f * d);
        expect_near(shifted, {0, 0.3f / r, 0.5f / r}, 1e-5f, "shift along the light");
        EXPECT_FLOAT_EQ(view.texel_size(512), 2.0f * r / 512.0f);
    }
}

TEST(LightView, DegenerateInputsStayFiniteOrAreRejected) {
    EXPECT_THROW(fit_light_view({{0, 0, 0}, 1.0f}, glm::vec3(0.0f)),
                 std::invalid_argument);
    EXPECT_THROW(fit_light_view({{0, 0, 0}, 1.0f}, glm::vec3(NAN, 0, 1)),
                 std::invalid_argument);
    const LightView point = fit_light_view({{1, 2, 3}, 0.0f}, {0, 0, 1});
    EXPECT_GT(point.radius, 0.0f);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            EXPECT_TRUE(std::isfinite(point.view_projection[i][j]));
}

// The scene's light is in eye space; the light view looks along it in object space.
TEST(LightView, SceneLightIsTakenFromEyeToObjectSpace) {
    const auto mesh = std::make_shared<const Mesh>(load_mesh("sphere:200"));
    const Technique& technique = find_technique("empirical");
    // Camera looking along -x (eye on +x): eye-space +z is object-space +x, eye +x is
    // object -z (right-handed, up +y).
    Scene scene =
        make_scene(mesh, technique, resolve_knob_values(knobs_for(technique), {}), 32, 32,
                   {1, 0, 0});
    scene.light.direction = {0, 0, 1};
    expect_near(light_direction_object(scene), {1, 0, 0}, 1e-5f, "eye +z");
    scene.light.direction = {1, 0, 0};
    expect_near(light_direction_object(scene), {0, 0, -1}, 1e-5f, "eye +x");
    const LightView view = scene_light_view(scene);
    expect_near(view.direction, {0, 0, -1}, 1e-5f, "light view direction");
    EXPECT_FLOAT_EQ(view.radius, scene.bounds.radius);
}

}  // namespace
}  // namespace lucent
