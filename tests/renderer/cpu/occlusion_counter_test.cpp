// The AO bake's escape counts: against analytic cones, against RayCaster's single rays
// on the mesh's own triangles (an independent scene), across query types and layouts,
// and the pairing of triangles into quads checked triangle by triangle.
#include "renderer/cpu/occlusion_counter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "renderer/core/mesh.h"
#include "renderer/cpu/ambient_occlusion_directions.h"
#include "renderer/cpu/ray_caster.h"

namespace lucent {
namespace {

constexpr OcclusionQuery kQueries[] = {OcclusionQuery::single, OcclusionQuery::packet8,
                                       OcclusionQuery::stream};
constexpr OcclusionScene kLayouts[] = {OcclusionScene::paired_quads,
                                       OcclusionScene::triangles};

TEST(OcclusionCounter, CountsRaysThatMissEverything) {
    const Mesh sphere = load_mesh("sphere:4000");
    // From (0, 0, 3) the unit sphere fills a cone of half-angle asin(1/3) around -Z.
    std::vector<glm::vec3> directions;
    int expected_escaping = 0;
    for (int i = 0; i < 200; ++i) {
        const float angle = 3.14159265f * (i + 0.5f) / 200.0f;  // from -Z towards +Z
        directions.push_back({std::sin(angle), 0.0f, -std::cos(angle)});
        if (angle > std::asin(1.0f / 3.0f) + 0.01f)
            ++expected_escaping;
        else if (angle < std::asin(1.0f / 3.0f) - 0.01f) {
        } else
            directions.pop_back();  // too close to the silhouette to call
    }
    for (const OcclusionScene layout : kLayouts) {
        const OcclusionCounter counter(sphere, layout);
        for (const OcclusionQuery query : kQueries) {
            EXPECT_EQ(counter.count_escaping({0.0f, 0.0f, 3.0f}, directions, 0.0f, query),
                      static_cast<std::size_t>(expected_escaping))
                << int(query);
            EXPECT_EQ(counter.count_escaping({0.0f, 0.0f, NAN}, directions, 0.0f, query),
                      directions.size());
        }
    }
}

// The query types and layouts are the same rays through different Embree entry points
// and scenes: each ray's answer, checked one at a time with RayCaster::occluded on the
// triangles, adds up to the same count, including counts that are not a multiple of a
// packet (1, 7, 9, 333 rays).
TEST(OcclusionCounter, EveryQueryAndLayoutCountsTheSameRaysAsOneAtATime) {
    const Mesh knot = load_mesh("torus_knot:4000");
    const RayCaster caster(knot);
    std::mt19937 engine(11);
    std::normal_distribution<float> gauss;
    std::size_t all = 0, all_escaping = 0;
    const OcclusionCounter quads(knot), triangles(knot, OcclusionScene::triangles);
    for (const std::size_t count : {1u, 7u, 9u, 333u}) {
        // Just above a vertex, as the AO bake starts its rays.
        const std::size_t vertex = (count * 997) % knot.vertex_count();
        const glm::vec3 origin = knot.positions[vertex] + 1e-3f * knot.normals[vertex];
        std::vector<glm::vec3> directions;
        std::size_t expected = 0;
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3 d =
                glm::normalize(glm::vec3(gauss(engine), gauss(engine), gauss(engine)));
            directions.push_back(d);
            if (!caster.occluded(origin, d, 0.0f, std::numeric_limits<float>::infinity()))
                ++expected;
        }
        all += count;
        all_escaping += expected;
        for (const OcclusionCounter* counter : {&quads, &triangles})
            for (const OcclusionQuery query : kQueries)
                EXPECT_EQ(counter->count_escaping(origin, directions, 0.0f, query),
                          expected)
                    << count << " rays, query " << int(query);
    }
    EXPECT_GT(all_escaping, all / 10);  // both outcomes are exercised
    EXPECT_LT(all_escaping, all - all / 10);
}

// The bake's own rays from every vertex of two meshes: quads and triangles answer every
// vertex alike, so pairing leaves the AO unchanged.
TEST(OcclusionCounter, QuadsAndTrianglesGiveTheBakeTheSameCounts) {
    const AoDirections lattice(64);
    for (const char* spec : {"torus_knot:4000", "hand:4000"}) {
        const Mesh mesh = load_mesh(spec);
        const OcclusionCounter quads(mesh), triangles(mesh, OcclusionScene::triangles);
        // Greedy pairing leaves a few alone (each then a quad of its own).
        EXPECT_GE(quads.paired_triangles(), mesh.face_count() * 95 / 100) << spec;
        EXPECT_EQ(quads.primitives(), mesh.face_count() - quads.paired_triangles() / 2)
            << spec;
        const float offset = 1e-4f * mesh.bounding_sphere().radius;
        std::vector<glm::vec3> directions;
        std::size_t differing = 0, escaped = 0;
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            lattice.generate(v, mesh.normals[v], directions);
            const glm::vec3 origin = mesh.positions[v] + offset * mesh.normals[v];
            const std::size_t a = quads.count_escaping(origin, directions);
            differing += a != triangles.count_escaping(origin, directions);
            escaped += a;
        }
        EXPECT_EQ(differing, 0u) << spec;
        EXPECT_GT(escaped, 0u);
        EXPECT_LT(escaped, mesh.vertex_count() * 64);
    }
}

// Each quad's two triangles, (v0, v1, v3) and (v2, v3, v1), are input triangles in their
// own cyclic order; every input triangle is in exactly one quad.
TEST(PairTriangles, CoversEveryTriangleOnceInItsOwnWinding) {
    const auto canonical = [](glm::uvec3 t) {  // the rotation starting at the least index
        while (t.x > t.y || t.x > t.z) t = {t.y, t.z, t.x};
        return t;
    };
    const auto key = [](glm::uvec3 t) { return std::tuple(t.x, t.y, t.z); };
    for (const char* spec : {"sphere:2000", "torus_knot:4000", "hand:4000", "wave"}) {
        const Mesh mesh = load_mesh(spec);
        std::map<std::tuple<unsigned, unsigned, unsigned>, int> remaining;
        for (const glm::uvec3& t : mesh.triangles) ++remaining[key(canonical(t))];
        const PairedTriangles paired = pair_triangles(mesh.triangles);
        std::size_t decoded = 0;
        for (const glm::uvec4& q : paired.quads) {
            for (const glm::uvec3 t :
                 {glm::uvec3(q.x, q.y, q.w), glm::uvec3(q.z, q.w, q.y)}) {
                if (t.y == t.z || t.x == t.y || t.x == t.z)
                    continue;  // the unpaired filler
                auto it = remaining.find(key(canonical(t)));
                ASSERT_TRUE(it != remaining.end() && it->second > 0)
                    << spec << ": quad names a triangle not in the mesh (or twice)";
                --it->second;
                ++decoded;
            }
        }
        EXPECT_EQ(decoded, mesh.face_count()) << spec;
        EXPECT_LE(paired.quads.size(), mesh.face_count());
        EXPECT_EQ(paired.quads.size(), mesh.face_count() - paired.paired / 2) << spec;
    }
    // Closed meshes pair almost completely (greedily, in triangle order); a lone
    // triangle or one wound against its neighbour stays alone (a, b, c, c).
    EXPECT_GE(pair_triangles(load_mesh("torus:2000").triangles).paired, 1950u);
    const PairedTriangles lone = pair_triangles({{0, 1, 2}});
    ASSERT_EQ(lone.quads.size(), 1u);
    EXPECT_EQ(lone.quads[0], glm::uvec4(0, 1, 2, 2));
    EXPECT_EQ(pair_triangles({{0, 1, 2}, {0, 1, 3}}).paired, 0u);  // edge (0,1) both ways
    EXPECT_EQ(pair_triangles({{0, 1, 2}, {1, 0, 3}}).paired, 2u);
    EXPECT_EQ(pair_triangles({{0, 1, 2}, {1, 0, 2}}).paired,
              0u);  // a double-sided sliver
    EXPECT_TRUE(pair_triangles({}).quads.empty());
}

}  // namespace
}  // namespace lucent
