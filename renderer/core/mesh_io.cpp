// Mesh files through Assimp: every mesh in the file is flattened into one (node
// transforms applied), triangulated, identical vertices joined; then cleaned here:
// triangles touching a non-finite vertex or with zero area are dropped, unused vertices
// removed, and missing or zero-length normals replaced by smooth ones.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/mesh.h"
#include "core/mesh_sources.h"

namespace lucent {

namespace {

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Twice the area is |cross|; call a triangle degenerate when that is zero relative to
// its longest edge squared (collinear or coincident corners).
bool degenerate(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const double longest = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b),
                                      glm::dot(a - c, a - c)});
    return !(glm::length(glm::cross(b - a, c - a)) > 1e-12 * longest) || longest == 0.0;
}

}  // namespace

Mesh load_mesh_file(const std::string& path) {
    std::error_code error;
    if (!std::filesystem::exists(path, error))
        throw MeshError(path + ": no such file (and not a built-in mesh name)");
    if (std::filesystem::is_directory(path, error))
        throw MeshError(path + ": is a directory, not a mesh file");

    Assimp::Importer importer;
    // Points and lines carry no surface: drop them during import.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene = importer.ReadFile(
        path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                  aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (scene == nullptr) throw MeshError(path + ": Assimp: " + importer.GetErrorString());

    // Merge all meshes, cleaning as we go.
    Mesh mesh;
    mesh.name = path;
    bool all_have_normals = true;
    std::size_t faces_in_file = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
        all_have_normals = all_have_normals && scene->mMeshes[m]->HasNormals();
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::uvec3> triangles;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* source = scene->mMeshes[m];
        const auto base = static_cast<unsigned>(positions.size());
        for (unsigned v = 0; v < source->mNumVertices; ++v) {
            const aiVector3D& p = source->mVertices[v];
            positions.emplace_back(p.x, p.y, p.z);
            if (all_have_normals) {
                const aiVector3D& n = source->mNormals[v];
                normals.emplace_back(n.x, n.y, n.z);
            }
        }
        faces_in_file += source->mNumFaces;
        for (unsigned f = 0; f < source->mNumFaces; ++f) {
            const aiFace& face = source->mFaces[f];
            if (face.mNumIndices != 3) continue;
            const glm::uvec3 t(base + face.mIndices[0], base + face.mIndices[1],
                               base + face.mIndices[2]);
            if (!finite(positions[t.x]) || !finite(positions[t.y]) || !finite(positions[t.z]))
                continue;
            if (degenerate(positions[t.x], positions[t.y], positions[t.z])) continue;
            triangles.push_back(t);
        }
    }
    if (triangles.empty())
        throw MeshError(path + ": no usable triangles (" + std::to_string(faces_in_file) +
                        " faces in the file, none with a finite non-zero area)");

    // Keep only referenced vertices, renumbered in order of first use.
    std::vector<unsigned> remap(positions.size(), ~0u);
    for (glm::uvec3& t : triangles)
        for (int k = 0; k < 3; ++k) {
            unsigned& target = remap[t[k]];
            if (target == ~0u) {
                target = static_cast<unsigned>(mesh.positions.size());
                mesh.positions.push_back(positions[t[k]]);
                if (all_have_normals) mesh.normals.push_back(normals[t[k]]);
            }
            t[k] = target;
        }
    mesh.triangles = std::move(triangles);
    finalize_mesh(mesh);  // smooth normals when missing; zero or NaN normals replaced
    return mesh;
}

}  // namespace lucent
