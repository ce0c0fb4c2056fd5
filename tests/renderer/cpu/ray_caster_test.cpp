// RayCaster against analytic distances: the built-in sphere has vertices on its poles
// and the torus vertices where the axis-aligned rays below cross it, so those hits are
// exact; rays through edges and vertices must give an even number of layers.
#include "renderer/cpu/ray_caster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <thread>

#include "renderer/core/mesh.h"

namespace lucent {
namespace {

TEST(RayCaster, RayThroughSphereCentreHitsAtDMinusRAndDPlusR) {
    const Mesh sphere = load_mesh("sphere:4000");
    const RayCaster caster(sphere);
    const float d = 3.0f;
    const std::vector<RayHit> layers =
        caster.hits({0.0f, 0.0f, d}, {0.0f, 0.0f, -2.0f}, 8);
    ASSERT_EQ(layers.size(), 2u);
    EXPECT_NEAR(layers[0].distance, d - 1.0f, 1e-5f);
    EXPECT_NEAR(layers[1].distance, d + 1.0f, 1e-5f);
    // Front face toward the ray, back face away from it.
    EXPECT_GT(layers[0].geometric_normal.z, 0.5f);
    EXPECT_LT(layers[1].geometric_normal.z, -0.5f);
}

TEST(RayCaster, ObliqueRaysThroughTheCentreMatchTheSphereToMeshAccuracy) {
    const Mesh sphere = load_mesh("sphere:30000");
    const RayCaster caster(sphere);
    for (int i = 0; i < 50; ++i) {
        const glm::vec3 dir = glm::normalize(
            glm::vec3(std::sin(i * 1.3f), std::cos(i * 0.7f), std::sin(i * 2.9f + 0.3f)));
        const glm::vec3 origin = -2.5f * dir;
        const std::vector<RayHit> layers = caster.hits(origin, dir, 4);
        ASSERT_EQ(layers.size(), 2u);
        // Inscribed polyhedron: hits lie inside the sphere, by at most ~1e-3 at 30K
        // faces.
        EXPECT_GE(layers[0].distance, 1.5f - 1e-5f);
        EXPECT_NEAR(layers[0].distance, 1.5f, 1e-3f);
        EXPECT_LE(layers[1].distance, 3.5f + 1e-5f);
        EXPECT_NEAR(layers[1].distance, 3.5f, 1e-3f);
    }
}

TEST(RayCaster, SideOnTorusGivesFourLayersAtAnalyticDistances) {
    const Mesh torus = load_mesh("torus:30000");  // radii 1 and 0.4, axis Y
    const RayCaster caster(torus);
    const std::vector<RayHit> layers =
        caster.hits({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, -1.0f}, 8);
    ASSERT_EQ(layers.size(), 4u);
    const float expected[] = {3.0f - 1.4f, 3.0f - 0.6f, 3.0f + 0.6f, 3.0f + 1.4f};
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(layers[i].distance, expected[i], 1e-5f) << i;
    EXPECT_EQ(caster.hits({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, -1.0f}, 2).size(), 2u);
}

TEST(RayCaster, EveryRayOfAGridCrossesClosedMeshesAnEvenNumberOfTimes) {
    // Many of these rays pass exactly through shared edges and vertices (the grid is
    // aligned with the meshes' symmetry planes): a duplicate or missed hit shows up as
    // an odd count.
    for (const char* spec :
         {"sphere:4000", "torus:4000", "torus_knot:8000", "hand:8000"}) {
        const Mesh mesh = load_mesh(spec);
        const RayCaster caster(mesh);
        const BoundingSphere bound = mesh.bounding_sphere();
        int odd = 0, hit_rays = 0;
        for (int y = -32; y <= 32; ++y)
            for (int x = -32; x <= 32; ++x) {
                const glm::vec3 origin =
                    bound.centre + bound.radius * glm::vec3(x / 32.0f, y / 32.0f, 2.0f);
                const auto layers = caster.hits(origin, {0.0f, 0.0f, -1.0f}, 64);
                if (layers.size() % 2 != 0) ++odd;
                if (!layers.empty()) ++hit_rays;
                for (std::size_t i = 1; i < layers.size(); ++i)
                    ASSERT_GT(layers[i].distance, layers[i - 1].distance);
            }
        EXPECT_EQ(odd, 0) << spec;
        EXPECT_GT(hit_rays, 100) << spec;
    }
}

TEST(RayCaster, FirstHitRespectsTheDistanceInterval) {
    const RayCaster caster(load_mesh("sphere:4000"));
    const glm::vec3 origin(0.0f, 0.0f, 3.0f), down(0.0f, 0.0f, -1.0f);
    EXPECT_FALSE(caster.first_hit(origin, down, 0.0f, 1.9f).has_value());
    ASSERT_TRUE(caster.first_hit(origin, down, 2.1f).has_value());
    EXPECT_NEAR(caster.first_hit(origin, down, 2.1f)->distance, 4.0f, 1e-5f);
    EXPECT_FALSE(caster.first_hit(origin, -down).has_value());  // pointing away
    EXPECT_FALSE(caster.occluded(origin, down, 0.0f, 1.9f));
    EXPECT_TRUE(caster.occluded(origin, down, 0.0f, 2.1f));
    EXPECT_FALSE(caster.occluded(origin, -down, 0.0f, 100.0f));
}

TEST(RayCaster, RejectsTrianglesPastTheLastVertex) {
    Mesh broken = load_mesh("sphere:400");
    broken.triangles.push_back({0, 1, static_cast<unsigned>(broken.vertex_count())});
    EXPECT_THROW(RayCaster{broken}, std::invalid_argument);
}

TEST(RayCaster, UnusableRaysHitNothing) {
    const RayCaster caster(load_mesh("sphere:4000"));
    EXPECT_FALSE(caster.first_hit({0, 0, 3}, {0, 0, 0}).has_value());
    EXPECT_FALSE(caster.first_hit({0, 0, NAN}, {0, 0, -1}).has_value());
    EXPECT_TRUE(caster.hits({0, 0, 3}, {0, 0, 0}, 4).empty());
    EXPECT_FALSE(caster.occluded({0, 0, 3}, {NAN, 0, 0}, 0.0f, 10.0f));
}

TEST(RayCaster, ConcurrentQueriesAgreeWithSerialOnes) {
    const RayCaster caster(load_mesh("torus_knot:8000"));
    auto ray = [](int i) {
        return std::pair{glm::vec3(std::sin(i * 0.37f), std::cos(i * 0.11f), 4.0f),
                         glm::vec3(std::sin(i * 0.05f) * 0.2f, 0.1f, -1.0f)};
    };
    constexpr int kRays = 4000;
    std::vector<std::size_t> serial(kRays);
    for (int i = 0; i < kRays; ++i)
        serial[i] = caster.hits(ray(i).first, ray(i).second, 16).size();
    std::vector<std::size_t> parallel(kRays);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int i = t; i < kRays; i += 4)
                parallel[i] = caster.hits(ray(i).first, ray(i).second, 16).size();
        });
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(serial, parallel);
}

}  // namespace
}  // namespace lucent
