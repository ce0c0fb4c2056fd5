// Meshes with UVs and tangent frames (issue 14 section 1): the built-in sheets, their
// square world-space texels, tangents along +u, UV seams kept through file loading, and
// the mesh hash covering UVs.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "renderer/core/mesh.h"

namespace lucent {
namespace {

TEST(SheetMeshes, HaveTheThesisTriangleCounts) {
    EXPECT_EQ(load_mesh("square").face_count(), 2u);
    EXPECT_EQ(load_mesh("wave").face_count(), 800u);
    EXPECT_EQ(load_mesh("wave:12800").face_count(), 12800u);
    EXPECT_EQ(load_mesh("drape").face_count(), 12800u);
    EXPECT_EQ(load_mesh("square:100").face_count(), 98u);  // 7 x 7 cells
    EXPECT_THROW(load_mesh("wave:1"), MeshError);
}

TEST(SheetMeshes, TexelsAreSquareInWorldSpaceAndTangentsFollowU) {
    for (const char* spec : {"square", "wave", "wave:12800"}) {
        const Mesh mesh = load_mesh(spec);
        ASSERT_TRUE(mesh.has_uvs()) << spec;
        ASSERT_EQ(mesh.tangents.size(), mesh.positions.size());
        for (const glm::uvec3& t : mesh.triangles) {
            // dp/du and dp/dv of the triangle: equal length, perpendicular.
            const glm::dvec3 e1 = glm::dvec3(mesh.positions[t.y] - mesh.positions[t.x]);
            const glm::dvec3 e2 = glm::dvec3(mesh.positions[t.z] - mesh.positions[t.x]);
            const glm::dvec2 s1 = glm::dvec2(mesh.uvs[t.y] - mesh.uvs[t.x]);
            const glm::dvec2 s2 = glm::dvec2(mesh.uvs[t.z] - mesh.uvs[t.x]);
            const double det = s1.x * s2.y - s2.x * s1.y;
            const glm::dvec3 du = (e1 * s2.y - e2 * s1.y) / det;
            const glm::dvec3 dv = (e2 * s1.x - e1 * s2.x) / det;
            ASSERT_NEAR(glm::length(du) / glm::length(dv), 1.0, 0.01) << spec;
            ASSERT_NEAR(glm::dot(du, dv) / (glm::length(du) * glm::length(dv)), 0.0,
                        0.01);
        }
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            const glm::vec3 n = mesh.normals[i], tan = glm::vec3(mesh.tangents[i]);
            ASSERT_NEAR(glm::length(tan), 1.0f, 1e-5f);
            ASSERT_NEAR(glm::dot(n, tan), 0.0f, 1e-5f);
            ASSERT_GT(tan.x, 0.5f) << spec;       // u grows along +x on every sheet
            ASSERT_EQ(mesh.tangents[i].w, 1.0f);  // and v along +y: right-handed
            ASSERT_GT(n.z, 0.5f);                 // facing +Z
        }
    }
}

TEST(SheetMeshes, HashCoversUvs) {
    Mesh a = load_mesh("square");
    const std::string before = a.content_hash;
    a.uvs[1].x += 0.25f;
    a.tangents.clear();
    finalize_mesh(a);
    EXPECT_NE(a.content_hash, before);
    // Meshes without UVs keep the hash they always had.
    EXPECT_EQ(compute_content_hash(a.positions, a.triangles),
              compute_content_hash(a.positions, a.triangles, {}));
}

TEST(SheetMeshes, FilesKeepUvsAndTheirSeams) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("lucent-uv-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    // Two quads sharing the edge x = 1, but with different uvs there (a seam): the
    // shared positions must stay two vertices each.
    std::ofstream(dir / "seam.obj")
        << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
           "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0\nvt 0.5 1\n"
           "vt 1.5 0\nvt 1.5 1\n"
           "f 1/1 2/2 3/3 4/4\nf 2/5 5/7 6/8 3/6\n";
    const Mesh seam = load_mesh((dir / "seam.obj").string());
    ASSERT_TRUE(seam.has_uvs());
    EXPECT_EQ(seam.vertex_count(), 8u);
    EXPECT_EQ(seam.face_count(), 4u);
    std::ofstream(dir / "plain.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n";
    const Mesh plain = load_mesh((dir / "plain.obj").string());
    EXPECT_FALSE(plain.has_uvs());
    EXPECT_TRUE(plain.tangents.empty());
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lucent
