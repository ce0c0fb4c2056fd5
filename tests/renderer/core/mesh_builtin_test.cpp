// Built-in meshes checked against topology and geometry facts that do not depend on how
// they are built: Euler characteristic for the genus, closed and consistently wound
// edges, analytic volumes, face budgets.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "renderer/core/mesh.h"
#include "tests/support/mesh_checks.h"

namespace lucent {
namespace {

constexpr double kPi = std::numbers::pi;

using test::closed_and_consistently_wound;
using test::signed_volume;

struct BuiltinCase {
    const char* name;
    int genus;
};

class BuiltinMeshTest : public ::testing::TestWithParam<BuiltinCase> {};

TEST_P(BuiltinMeshTest, HitsFaceBudgetWithinThreePercent) {
    for (const std::size_t budget : {4000u, 30000u}) {
        const Mesh mesh =
            load_mesh(std::string(GetParam().name) + ":" + std::to_string(budget));
        EXPECT_NEAR(double(mesh.face_count()), double(budget), 0.03 * budget)
            << mesh.name;
    }
    const Mesh by_default = load_mesh(GetParam().name);
    EXPECT_NEAR(double(by_default.face_count()), double(kDefaultFaceBudget),
                0.03 * kDefaultFaceBudget);
}

TEST_P(BuiltinMeshTest, IsClosedOrientableWithTheRightGenus) {
    const Mesh mesh = load_mesh(std::string(GetParam().name) + ":8000");
    EXPECT_TRUE(closed_and_consistently_wound(mesh));
    // Closed triangle mesh: E = 3F/2, so V - E + F = 2 - 2g gives V = F/2 + 2 - 2g.
    const long expected_vertices = long(mesh.face_count()) / 2 + 2 - 2 * GetParam().genus;
    EXPECT_EQ(long(mesh.vertex_count()), expected_vertices);
}

TEST_P(BuiltinMeshTest, IsMarkedAsBoundingASolidFacingOut) {
    const Mesh mesh = load_mesh(std::string(GetParam().name) + ":8000");
    EXPECT_TRUE(mesh.closed_facing_out);
    EXPECT_TRUE(bounds_solid_facing_out(mesh.positions, mesh.triangles));
}

TEST_P(BuiltinMeshTest, WindsOutwardWithUnitNormalsAndNoDegenerateFaces) {
    const Mesh mesh = load_mesh(std::string(GetParam().name) + ":8000");
    EXPECT_GT(signed_volume(mesh), 0.0);
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    for (const glm::vec3& n : mesh.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
    // Vertex normals point out of the surface: they agree with the faces around them
    // (checked at each triangle's corners; marching tetrahedra leaves the odd sliver
    // whose own normal is noise, hence 1 in 500).
    std::size_t disagreeing = 0;
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::vec3 face = glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                                          mesh.positions[t.z] - mesh.positions[t.x]);
        ASSERT_GT(glm::length(face), 0.0f);
        for (int k = 0; k < 3; ++k)
            if (glm::dot(face, mesh.normals[t[k]]) <= 0.0f) ++disagreeing;
    }
    EXPECT_LE(disagreeing, mesh.face_count() / 500)
        << "corners whose normal faces inward";
}

TEST_P(BuiltinMeshTest, BoundingSphereContainsEveryVertexAndIsTight) {
    const Mesh mesh = load_mesh(std::string(GetParam().name) + ":4000");
    const BoundingSphere sphere = mesh.bounding_sphere();
    for (const glm::vec3& p : mesh.positions)
        EXPECT_LE(glm::length(p - sphere.centre), sphere.radius);
    // Half the largest vertex distance is a lower bound on any enclosing radius; the
    // AABB/Ritter sphere stays within 1.25x of it on these shapes.
    float diameter_lower_bound = 0.0f;
    for (std::size_t i = 0; i < mesh.positions.size(); i += 7)
        for (std::size_t j = 0; j < mesh.positions.size(); j += 5)
            diameter_lower_bound = std::max(
                diameter_lower_bound, glm::length(mesh.positions[i] - mesh.positions[j]));
    EXPECT_LE(sphere.radius, 0.5f * diameter_lower_bound * 1.25f);
}

INSTANTIATE_TEST_SUITE_P(Builtins, BuiltinMeshTest,
                         ::testing::Values(BuiltinCase{"sphere", 0},
                                           BuiltinCase{"torus", 1},
                                           BuiltinCase{"torus_knot", 1},
                                           BuiltinCase{"hand", 0}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(BuiltinMesh, SphereMatchesTheUnitSphere) {
    const Mesh mesh = load_mesh("sphere:30000");
    for (const glm::vec3& p : mesh.positions) ASSERT_NEAR(glm::length(p), 1.0f, 1e-6f);
    const double volume = signed_volume(mesh), exact = 4.0 / 3.0 * kPi;
    EXPECT_LT(volume, exact);  // inscribed polyhedron
    EXPECT_NEAR(volume, exact, 0.003 * exact);
    const BoundingSphere sphere = mesh.bounding_sphere();
    EXPECT_NEAR(sphere.radius, 1.0f, 1e-4f);
    EXPECT_NEAR(glm::length(sphere.centre), 0.0f, 1e-4f);
}

TEST(BuiltinMesh, TorusMatchesTheAnalyticTorus) {
    const Mesh mesh = load_mesh("torus:30000");
    // Every vertex lies on the torus of radii (1, 0.4) around the Y axis.
    for (const glm::vec3& p : mesh.positions) {
        const float ring = std::hypot(p.x, p.z) - 1.0f;
        ASSERT_NEAR(std::hypot(ring, p.y), 0.4f, 1e-5f);
    }
    const double exact = 2.0 * kPi * kPi * 1.0 * 0.4 * 0.4;
    EXPECT_NEAR(signed_volume(mesh), exact, 0.005 * exact);
}

TEST(BuiltinMesh, TorusKnotHasThinAndThickParts) {
    // Distance of each vertex to the nearest knot-curve sample is the local tube radius.
    const Mesh mesh = load_mesh("torus_knot:8000");
    auto curve = [](double t) {
        const double r = 1.0 + 0.45 * std::cos(3 * t);
        return glm::dvec3(r * std::cos(2 * t), r * std::sin(2 * t),
                          0.45 * std::sin(3 * t));
    };
    std::vector<glm::dvec3> samples;
    for (int i = 0; i < 4000; ++i) samples.push_back(curve(2 * kPi * i / 4000));
    double thinnest = 1e9, thickest = 0.0;
    for (std::size_t v = 0; v < mesh.positions.size(); v += 3) {
        double nearest = 1e9;
        for (const glm::dvec3& s : samples)
            nearest = std::min(nearest, glm::length(glm::dvec3(mesh.positions[v]) - s));
        thinnest = std::min(thinnest, nearest);
        thickest = std::max(thickest, nearest);
    }
    EXPECT_NEAR(thinnest, 0.05, 0.01);
    EXPECT_NEAR(thickest, 0.25, 0.01);
}

TEST(BuiltinMesh, HandIsNonConvexWithThinFingers) {
    const Mesh mesh = load_mesh("hand:30000");
    // The fingertips rise far above the palm.
    double top_band_vertices = 0, total = double(mesh.vertex_count());
    for (const glm::vec3& p : mesh.positions)
        if (p.y > 1.0f) ++top_band_vertices;
    EXPECT_GT(top_band_vertices / total, 0.02) << "fingers reach above y = 1";
    // Along y = 1.0 (mid-finger) the cross-section is several separate thin pieces: a
    // row of sample points across x alternates inside/outside at least 8 times.
    auto inside = [&](glm::vec3 q) {
        // Point-in-mesh by ray parity along +Z (the hand is closed).
        int crossings = 0;
        for (const glm::uvec3& t : mesh.triangles) {
            const glm::vec3 a = mesh.positions[t.x], b = mesh.positions[t.y],
                            c = mesh.positions[t.z];
            const auto edge = [&](glm::vec3 p0, glm::vec3 p1) {
                return (p1.x - p0.x) * (q.y - p0.y) - (p1.y - p0.y) * (q.x - p0.x);
            };
            const float w0 = edge(b, c), w1 = edge(c, a), w2 = edge(a, b);
            if ((w0 > 0 && w1 > 0 && w2 > 0) || (w0 < 0 && w1 < 0 && w2 < 0)) {
                const float z = (w0 * a.z + w1 * b.z + w2 * c.z) / (w0 + w1 + w2);
                if (z > q.z) ++crossings;
            }
        }
        return crossings % 2 == 1;
    };
    int changes = 0;
    bool previous = false;
    for (int i = 0; i <= 200; ++i) {
        const bool now = inside({-1.0f + 1.7f * i / 200.0f, 1.0f, 0.02f});
        if (now != previous) ++changes;
        previous = now;
    }
    EXPECT_GE(changes, 8) << "four separate fingers cross y = 1";
}

TEST(BuiltinMesh, FaceBudgetSuffixesAndErrors) {
    EXPECT_NEAR(double(load_mesh("torus_knot:240k").face_count()), 240000.0,
                0.03 * 240000);
    EXPECT_THROW(load_mesh(""), MeshError);
    for (const char* bad :
         {"sphere:abc", "sphere:10", "sphere:", "torus:30kk", "hand:-5"}) {
        try {
            load_mesh(bad);
            ADD_FAILURE() << bad << " should be rejected";
        } catch (const MeshError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind(std::string(bad) + ": face budget", 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos);
        }
    }
}

TEST(BuiltinMesh, ContentHashIdentifiesTheGeometry) {
    const Mesh a = load_mesh("torus:4000"), b = load_mesh("torus:4000");
    EXPECT_EQ(a.content_hash.size(), 16u);
    EXPECT_EQ(a.content_hash.find_first_not_of("0123456789abcdef"), std::string::npos);
    EXPECT_EQ(a.content_hash, b.content_hash);
    EXPECT_NE(a.content_hash, load_mesh("torus:5000").content_hash);
    Mesh moved = a;
    moved.positions[17].x += 1e-6f;
    EXPECT_NE(compute_content_hash(moved.positions, moved.triangles), a.content_hash);
    Mesh rewound = a;
    std::swap(rewound.triangles[3].y, rewound.triangles[3].z);
    EXPECT_NE(compute_content_hash(rewound.positions, rewound.triangles), a.content_hash);
}

TEST(BuiltinMesh, NamesAreListed) {
    const std::vector<std::string> names = builtin_mesh_names();
    for (const char* name : {"sphere", "torus", "torus_knot", "hand"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
}

// What culling by facing relies on (Mesh::closed_facing_out), on meshes whose answer is
// known by construction: a tetrahedron wound outward, and ways of breaking it.
TEST(BoundsSolidFacingOut, AcceptsOnlyClosedSurfacesWoundOutward) {
    const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    // Counter-clockwise seen from outside: the normal (p1-p0)x(p2-p0) points away from
    // the opposite vertex.
    const std::vector<glm::uvec3> tetra = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    EXPECT_TRUE(bounds_solid_facing_out(p, tetra));

    std::vector<glm::uvec3> inward = tetra;
    for (auto& t : inward) std::swap(t.y, t.z);
    EXPECT_FALSE(bounds_solid_facing_out(p, inward)) << "closed but facing in";

    std::vector<glm::uvec3> hole(tetra.begin(), tetra.end() - 1);
    EXPECT_FALSE(bounds_solid_facing_out(p, hole)) << "a missing face";

    std::vector<glm::uvec3> flipped = tetra;
    std::swap(flipped[3].y, flipped[3].z);
    EXPECT_FALSE(bounds_solid_facing_out(p, flipped)) << "one face wound the other way";

    std::vector<glm::uvec3> doubled = tetra;
    doubled.push_back(tetra[3]);
    EXPECT_FALSE(bounds_solid_facing_out(p, doubled)) << "an edge shared three times";

    EXPECT_FALSE(bounds_solid_facing_out(p, {})) << "no triangles";
    EXPECT_FALSE(bounds_solid_facing_out(p, {{0, 1, 7}})) << "an index past the end";

    // Split vertices at bit-identical positions (a seam for normals or UVs) are one
    // vertex to the rasteriser: still closed.
    std::vector<glm::vec3> seam = p;
    seam.push_back(p[3]);  // index 4 sits on vertex 3
    std::vector<glm::uvec3> split = tetra;
    split[3] = {1, 2, 4};
    EXPECT_TRUE(bounds_solid_facing_out(seam, split));
    // ...but a vertex moved by one ulp is a crack.
    seam[4].z = std::nextafter(seam[4].z, 2.0f);
    EXPECT_FALSE(bounds_solid_facing_out(seam, split));

    // Two disjoint closed parts are closed.
    std::vector<glm::vec3> two = p;
    for (const glm::vec3& q : p) two.push_back(q + glm::vec3(5.0f, 0.0f, 0.0f));
    std::vector<glm::uvec3> both = tetra;
    for (const glm::uvec3& t : tetra) both.push_back(t + glm::uvec3(4u));
    EXPECT_TRUE(bounds_solid_facing_out(two, both));

    // The open sheets are not, and the flag travels with finalize_mesh.
    EXPECT_FALSE(load_mesh("square").closed_facing_out);
    EXPECT_FALSE(load_mesh("wave").closed_facing_out);
    Mesh tetrahedron;
    tetrahedron.positions = p;
    tetrahedron.triangles = tetra;
    finalize_mesh(tetrahedron);
    EXPECT_TRUE(tetrahedron.closed_facing_out);
}

}  // namespace
}  // namespace lucent
