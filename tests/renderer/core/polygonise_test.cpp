// Marching tetrahedra on fields with known zero sets: closed, outward, right genus, and
// enclosing the analytic volume.
#include "renderer/core/polygonise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/support/mesh_checks.h"

namespace lucent {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Polygonise, SphereFieldGivesAClosedGenusZeroSphere) {
    const Mesh mesh = polygonise([](glm::vec3 p) { return glm::length(p) - 1.0f; },
                                 glm::vec3(-1.2f), glm::vec3(1.2f), 0.05f);
    EXPECT_TRUE(test::closed_and_consistently_wound(mesh));
    EXPECT_EQ(long(mesh.vertex_count()), long(mesh.face_count()) / 2 + 2);
    EXPECT_NEAR(test::signed_volume(mesh), 4.0 / 3.0 * kPi, 0.01 * 4.0 / 3.0 * kPi);
    for (const glm::vec3& p : mesh.positions) ASSERT_NEAR(glm::length(p), 1.0f, 0.01f);
}

TEST(Polygonise, TorusFieldGivesGenusOne) {
    const auto torus = [](glm::vec3 p) {
        return std::hypot(std::hypot(p.x, p.z) - 1.0f, p.y) - 0.3f;
    };
    const Mesh mesh = polygonise(torus, glm::vec3(-1.5f), glm::vec3(1.5f), 0.04f);
    EXPECT_TRUE(test::closed_and_consistently_wound(mesh));
    EXPECT_EQ(long(mesh.vertex_count()), long(mesh.face_count()) / 2);
    const double volume = 2.0 * kPi * kPi * 1.0 * 0.3 * 0.3;
    EXPECT_NEAR(test::signed_volume(mesh), volume, 0.02 * volume);
}

TEST(Polygonise, FaceCountScalesWithTheInverseSquareOfTheCell) {
    const auto sphere = [](glm::vec3 p) { return glm::length(p) - 1.0f; };
    const double coarse =
        double(polygonise(sphere, glm::vec3(-1.2f), glm::vec3(1.2f), 0.08f).face_count());
    const double fine =
        double(polygonise(sphere, glm::vec3(-1.2f), glm::vec3(1.2f), 0.04f).face_count());
    EXPECT_NEAR(fine / coarse, 4.0, 0.4);
}

}  // namespace
}  // namespace lucent
