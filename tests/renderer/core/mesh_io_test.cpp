// Mesh files: small files written here (each format, plus degenerate, NaN, empty,
// missing and garbage input) and the shared test meshes, whose counts come from
// ../shared/meshes/README.md.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "renderer/core/mesh.h"
#include "tests/support/mesh_checks.h"
#include "tests/support/test_paths.h"

namespace lucent {
namespace {

using test::closed_and_consistently_wound;
using test::signed_volume;

std::string write_file(const std::string& dir, const std::string& name,
                       const std::string& contents) {
    const auto path = test::scratch_dir("mesh_io/" + dir) / name;
    std::ofstream(path, std::ios::binary) << contents;
    return path.string();
}

// Expects load_mesh(path) to throw a one-line MeshError starting "PATH: ".
void expect_one_line_error(const std::string& path, const std::string& reason_part) {
    try {
        const Mesh mesh = load_mesh(path);
        ADD_FAILURE() << path << " loaded with " << mesh.face_count() << " faces";
    } catch (const MeshError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_NE(what.find(reason_part), std::string::npos) << what;
    }
}

// Unit cube as six outward quads, plus a collinear triangle and one that repeats a
// corner; vertex 9 is used only by the collinear one.
constexpr const char* kCubeObj = R"(# unit cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
v 0.5 0 0
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
f 1 9 2
f 3 3 7
)";

TEST(MeshIo, ObjIsTriangulatedDegenerateFacesDroppedAndNormalsGenerated) {
    const Mesh mesh = load_mesh(write_file("obj", "cube.obj", kCubeObj));
    EXPECT_EQ(mesh.face_count(), 12u);
    EXPECT_EQ(mesh.vertex_count(), 8u);  // the collinear face's extra vertex is gone
    EXPECT_TRUE(closed_and_consistently_wound(mesh));
    EXPECT_NEAR(signed_volume(mesh), 1.0, 1e-6);
    // Angle-weighted normals: each corner sees three faces at 90 degrees each, however
    // the quads were split, so the normal points along the diagonal out of the cube.
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
        const glm::vec3 diagonal = glm::normalize(mesh.positions[i] - glm::vec3(0.5f));
        EXPECT_NEAR(glm::dot(mesh.normals[i], diagonal), 1.0f, 1e-5f) << i;
    }
    EXPECT_EQ(mesh.content_hash.size(), 16u);
    EXPECT_EQ(mesh.name, write_file("obj", "cube.obj", kCubeObj));
}

// 1e39 overflows a float to infinity.
TEST(MeshIo, TrianglesTouchingNonFiniteVerticesAreDropped) {
    const Mesh mesh =
        load_mesh(write_file("nan", "nan.obj",
                             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan nan nan\n"
                             "v 0 0 1\nv 1e39 0 0\nf 1 2 3\nf 1 4 2\nf 1 2 5\n"
                             "f 6 2 3\n"));
    EXPECT_EQ(mesh.face_count(), 2u);
    EXPECT_EQ(mesh.vertex_count(), 4u);
    for (const glm::vec3& p : mesh.positions) EXPECT_TRUE(std::isfinite(glm::length(p)));
    for (const glm::vec3& n : mesh.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
}

// Regular tetrahedron around the origin in ASCII PLY with normals: one zero, one
// unnormalised, two exact.
TEST(MeshIo, PlyNormalsAreKeptNormalisedAndZeroOnesReplaced) {
    const Mesh mesh = load_mesh(write_file("ply", "tetra.ply", R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
element face 4
property list uchar int vertex_indices
end_header
1 1 1 0 0 0
1 -1 -1 2 -2 -2
-1 1 -1 -0.57735027 0.57735027 -0.57735027
-1 -1 1 -0.57735027 -0.57735027 0.57735027
3 0 2 3
3 0 3 1
3 0 1 2
3 1 3 2
)"));
    ASSERT_EQ(mesh.face_count(), 4u);
    ASSERT_EQ(mesh.vertex_count(), 4u);
    EXPECT_TRUE(closed_and_consistently_wound(mesh));
    EXPECT_GT(signed_volume(mesh), 0.0);
    // By symmetry every vertex normal (given or generated) points away from the centre.
    for (std::size_t i = 0; i < 4; ++i)
        EXPECT_NEAR(glm::dot(mesh.normals[i], glm::normalize(mesh.positions[i])), 1.0f,
                    1e-5f)
            << i;
}

TEST(MeshIo, StlFacetNormalsAreWeldedIntoSmoothOnes) {
    std::string stl = "solid tetra\n";
    const glm::vec3 v[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    const int faces[4][3] = {{0, 2, 3}, {0, 3, 1}, {0, 1, 2}, {1, 3, 2}};
    for (const auto& f : faces) {
        const glm::vec3 n =
            glm::normalize(glm::cross(v[f[1]] - v[f[0]], v[f[2]] - v[f[0]]));
        stl += "facet normal " + std::to_string(n.x) + " " + std::to_string(n.y) + " " +
               std::to_string(n.z) + "\nouter loop\n";
        for (int k : f)
            stl += "vertex " + std::to_string(v[k].x) + " " + std::to_string(v[k].y) +
                   " " + std::to_string(v[k].z) + "\n";
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid tetra\n";
    const Mesh mesh = load_mesh(write_file("stl", "tetra.stl", stl));
    EXPECT_EQ(mesh.face_count(), 4u);
    EXPECT_EQ(mesh.vertex_count(), 4u);
    EXPECT_TRUE(closed_and_consistently_wound(mesh));
    EXPECT_NEAR(signed_volume(mesh), 8.0 / 3.0, 1e-5);  // a third of the 2x2x2 cube
    for (std::size_t i = 0; i < 4; ++i)
        EXPECT_NEAR(glm::dot(mesh.normals[i], glm::normalize(mesh.positions[i])), 1.0f,
                    1e-5f);
}

TEST(MeshIo, OffQuadsAreTriangulated) {
    const Mesh mesh = load_mesh(write_file("off", "cube.off", R"(OFF
8 6 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
)"));
    EXPECT_EQ(mesh.face_count(), 12u);
    EXPECT_TRUE(closed_and_consistently_wound(mesh));
    EXPECT_NEAR(signed_volume(mesh), 1.0, 1e-6);
}

std::string base64(const std::string& bytes) {
    static constexpr char kDigits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        std::uint32_t chunk = 0;
        const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
        for (std::size_t k = 0; k < 3; ++k)
            chunk = chunk << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
        for (std::size_t k = 0; k < 4; ++k)
            out += k <= n ? kDigits[(chunk >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

TEST(MeshIo, GltfNodeTransformsAreApplied) {
    // The tetrahedron again, as glTF 2.0 with an embedded buffer, moved by its node.
    const float positions[12] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
    const std::uint16_t indices[12] = {0, 2, 3, 0, 3, 1, 0, 1, 2, 1, 3, 2};
    std::string buffer(reinterpret_cast<const char*>(positions), sizeof positions);
    buffer.append(reinterpret_cast<const char*>(indices), sizeof indices);
    const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "translation": [10, 20, 30]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,)" +
                             base64(buffer) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [-1, -1, -1], "max": [1, 1, 1]},
                {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]})";
    const Mesh mesh = load_mesh(write_file("gltf", "tetra.gltf", gltf));
    EXPECT_EQ(mesh.face_count(), 4u);
    EXPECT_EQ(mesh.vertex_count(), 4u);
    const BoundingSphere sphere = mesh.bounding_sphere();
    EXPECT_NEAR(glm::length(sphere.centre - glm::vec3(10, 20, 30)), 0.0f, 1e-4f);
    EXPECT_NEAR(sphere.radius, std::sqrt(3.0f), 1e-4f);
    EXPECT_NEAR(signed_volume(mesh), 8.0 / 3.0, 1e-3);
}

TEST(MeshIo, PlyTriangleStripsAlternateWindingAndRestart) {
    // Two strips on the z = 0 plane (a 3x1 quad row and a single quad), separated by -1:
    // every triangle must face +Z once the strip's alternating winding is undone.
    const Mesh mesh = load_mesh(write_file("strips", "strips.ply", R"(ply
format ascii 1.0
element vertex 12
property float x
property float y
property float z
element tristrips 1
property list int int vertex_indices
end_header
0 0 0
0 1 0
1 0 0
1 1 0
2 0 0
2 1 0
3 0 0
3 1 0
5 0 0
5 1 0
6 0 0
6 1 0
13 1 0 3 2 5 4 7 6 -1 9 8 11 10
)"));
    EXPECT_EQ(mesh.face_count(), 8u);
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::vec3 n = glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                                       mesh.positions[t.z] - mesh.positions[t.x]);
        EXPECT_GT(n.z, 0.0f);
    }
}

TEST(MeshIo, BadFilesGiveOneLineNamingTheFile) {
    expect_one_line_error((test::scratch_dir("mesh_io/missing") / "nope.obj").string(),
                          "no such file");
    expect_one_line_error(test::scratch_dir("mesh_io/dir").string(), "directory");
    std::mt19937 random(7);
    std::string garbage(4096, '\0');
    for (char& c : garbage) c = static_cast<char>(random());
    for (const char* name : {"garbage.obj", "garbage.ply", "garbage.stl", "garbage.xyz"})
        expect_one_line_error(write_file("garbage", name, garbage), "");
    expect_one_line_error(write_file("empty", "points.obj", "v 0 0 0\nv 1 1 1\n"), "");
    expect_one_line_error(
        write_file("degenerate", "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
        "no usable triangles");
    expect_one_line_error(write_file("range", "range.ply", R"(ply
format ascii 1.0
element vertex 3
property float x
property float y
property float z
element tristrips 1
property list int int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
3 0 1 7
)"),
                          "vertex 7");
    expect_one_line_error(write_file("truncated", "short.ply", R"(ply
format binary_little_endian 1.0
element vertex 3
property float x
property float y
property float z
element tristrips 1
property list int int vertex_indices
end_header
abc)"),
                          "truncated");
}

// The shared meshes, with the counts their README gives (faces; referenced vertices,
// after welding for files that split vertices by normal).
struct SharedMesh {
    const char* file;
    std::size_t faces, vertices;
    bool closed;
};

class SharedMeshTest : public ::testing::TestWithParam<SharedMesh> {};

TEST_P(SharedMeshTest, LoadsWithTheDocumentedCounts) {
    const std::string relative = std::string("meshes/") + GetParam().file;
    LUCENT_REQUIRE_SHARED(relative);
    const Mesh mesh = load_mesh((test::shared_dir() / relative).string());
    EXPECT_EQ(mesh.face_count(), GetParam().faces);
    EXPECT_EQ(mesh.vertex_count(), GetParam().vertices);
    for (const glm::vec3& n : mesh.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
    if (GetParam().closed) {
        EXPECT_TRUE(closed_and_consistently_wound(mesh));
        EXPECT_GT(signed_volume(mesh), 0.0);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Shared, SharedMeshTest,
    ::testing::Values(SharedMesh{"bunny-watertight-odedstein.obj", 6598, 3301, true},
                      SharedMesh{"decimated-max.obj", 10540, 5272, true},
                      SharedMesh{"fertility.off", 9000, 4494, true},
                      SharedMesh{"igea.ply", 268686, 134345, true},
                      SharedMesh{"stanford-bunny.obj", 69451, 34834, false},
                      SharedMesh{"dragon_vrip_res4.ply", 11102, 5203, false},
                      SharedMesh{"happy_vrip_res3.ply", 67240, 32316, false},
                      SharedMesh{"suzanne.obj", 968, 505, false}),
    [](const auto& info) {
        std::string name = info.param.file;
        for (char& c : name)
            if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        return name;
    });

}  // namespace
}  // namespace lucent
