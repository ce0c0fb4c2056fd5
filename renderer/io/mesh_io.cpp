// Mesh files: read through Assimp (every mesh in the file flattened into one, node
// transforms applied, polygons triangulated), except PLY triangle strips, which Assimp
// 5.2 misreads and ply_strips.cpp reads. Then cleaned here, whatever the format:
//   - vertices at the same position are welded (files with per-face normals, like STL
//     or some OBJs, otherwise split every corner and leave no shared edges);
//   - file normals are kept unless welding found them disagreeing (then smooth normals
//     replace them all); missing, NaN or zero-length normals become smooth normals;
//   - triangles touching a non-finite vertex or with zero area are dropped, and unused
//     vertices removed. A file left with no triangle is an error.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <unordered_map>

#include "common/content_hash.h"
#include "renderer/core/mesh.h"
#include "renderer/core/mesh_builtin.h"
#include "renderer/io/mesh_sources.h"

namespace lucent {

namespace {

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Zero area relative to the longest edge squared (collinear or coincident corners).
bool degenerate(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const double longest = std::max(
        {glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    return longest == 0.0 || !(glm::length(glm::cross(b - a, c - a)) > 1e-12 * longest);
}

RawMesh read_with_assimp(const std::string& path) {
    Assimp::Importer importer;
    // Points and lines carry no surface: drop them during import.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    // No aiProcess_JoinIdenticalVertices: it compares with a tolerance that NaN passes,
    // so it would weld a NaN vertex onto a valid one; clean() welds exactly instead.
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                    aiProcess_SortByPType);
    if (scene == nullptr)
        throw MeshError(path + ": Assimp: " + importer.GetErrorString());
    RawMesh raw;
    bool all_have_normals = scene->mNumMeshes > 0, all_have_uvs = scene->mNumMeshes > 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        all_have_normals = all_have_normals && scene->mMeshes[m]->HasNormals();
        all_have_uvs = all_have_uvs && scene->mMeshes[m]->HasTextureCoords(0);
    }
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* source = scene->mMeshes[m];
        const auto base = static_cast<unsigned>(raw.positions.size());
        for (unsigned v = 0; v < source->mNumVertices; ++v) {
            const aiVector3D& p = source->mVertices[v];
            raw.positions.emplace_back(p.x, p.y, p.z);
            if (all_have_normals) {
                const aiVector3D& n = source->mNormals[v];
                raw.normals.emplace_back(n.x, n.y, n.z);
            }
            if (all_have_uvs) {
                const aiVector3D& uv = source->mTextureCoords[0][v];
                raw.uvs.emplace_back(uv.x, uv.y);
            }
        }
        raw.faces_in_file += source->mNumFaces;
        for (unsigned f = 0; f < source->mNumFaces; ++f) {
            const aiFace& face = source->mFaces[f];
            if (face.mNumIndices == 3)
                raw.triangles.emplace_back(base + face.mIndices[0],
                                           base + face.mIndices[1],
                                           base + face.mIndices[2]);
        }
    }
    return raw;
}

struct PositionKey {
    std::uint32_t bits[5];  // position, then uv (0 when the file has none)
    bool operator==(const PositionKey& other) const {
        return std::memcmp(bits, other.bits, sizeof bits) == 0;
    }
};
struct PositionKeyHash {
    std::size_t operator()(const PositionKey& k) const {
        return static_cast<std::size_t>(
            common::ContentHash().bytes(k.bits, sizeof k.bits).result());
    }
};

PositionKey key_of(glm::vec3 p, glm::vec2 uv) {
    PositionKey key;
    const float values[5] = {p.x, p.y, p.z, uv.x, uv.y};
    for (int k = 0; k < 5; ++k) {
        const float v = values[k] == 0.0f ? 0.0f : values[k];  // weld -0 with +0
        std::memcpy(&key.bits[k], &v, sizeof v);
    }
    return key;
}

// Welds equal (position, uv) pairs, drops unusable triangles and unused vertices.
Mesh clean(const std::string& path, RawMesh raw) {
    std::unordered_map<PositionKey, unsigned, PositionKeyHash> welded;
    std::vector<unsigned> representative(raw.positions.size());
    bool normals_agree = !raw.normals.empty();
    // A file with any non-finite uv keeps none (tangents from NaN uvs would be NaN).
    bool with_uvs = raw.uvs.size() == raw.positions.size() && !raw.uvs.empty();
    for (std::size_t i = 0; with_uvs && i < raw.uvs.size(); ++i)
        with_uvs = std::isfinite(raw.uvs[i].x) && std::isfinite(raw.uvs[i].y);
    for (std::size_t i = 0; i < raw.positions.size(); ++i) {
        const glm::vec2 uv = with_uvs ? raw.uvs[i] : glm::vec2(0.0f);
        const auto [it, inserted] =
            welded.try_emplace(key_of(raw.positions[i], uv), static_cast<unsigned>(i));
        representative[i] = it->second;
        if (!inserted && normals_agree &&
            glm::dot(raw.normals[i], raw.normals[it->second]) <
                0.9999f * glm::length(raw.normals[i]) *
                    glm::length(raw.normals[it->second]))
            normals_agree = false;
    }
    Mesh mesh;
    mesh.name = path;
    std::vector<unsigned> remap(raw.positions.size(), ~0u);
    for (glm::uvec3 t : raw.triangles) {
        if (t.x >= raw.positions.size() || t.y >= raw.positions.size() ||
            t.z >= raw.positions.size())
            throw MeshError(path + ": a face refers to vertex " +
                            std::to_string(std::max({t.x, t.y, t.z})) + " of only " +
                            std::to_string(raw.positions.size()));
        t = {representative[t.x], representative[t.y], representative[t.z]};
        const glm::vec3 a = raw.positions[t.x], b = raw.positions[t.y],
                        c = raw.positions[t.z];
        if (!finite(a) || !finite(b) || !finite(c) || degenerate(a, b, c)) continue;
        for (int k = 0; k < 3; ++k) {
            unsigned& target = remap[t[k]];
            if (target == ~0u) {
                target = static_cast<unsigned>(mesh.positions.size());
                mesh.positions.push_back(raw.positions[t[k]]);
                if (normals_agree) mesh.normals.push_back(raw.normals[t[k]]);
                if (with_uvs) mesh.uvs.push_back(raw.uvs[t[k]]);
            }
            t[k] = target;
        }
        mesh.triangles.push_back(t);
    }
    if (mesh.triangles.empty())
        throw MeshError(path + ": no usable triangles (" +
                        std::to_string(raw.faces_in_file) +
                        " faces in the file, none with three finite, distinct corners)");
    finalize_mesh(mesh);  // smooth normals when missing; zero or NaN normals replaced
    return mesh;
}

}  // namespace

Mesh load_mesh_file(const std::string& path) {
    std::error_code error;
    if (!std::filesystem::exists(path, error))
        throw MeshError(path + ": no such file (and not a built-in mesh name)");
    if (std::filesystem::is_directory(path, error))
        throw MeshError(path + ": is a directory, not a mesh file");
    if (std::optional<RawMesh> strips = read_ply_triangle_strips(path))
        return clean(path, std::move(*strips));
    return clean(path, read_with_assimp(path));
}

Mesh load_mesh(const std::string& spec) {
    if (spec.empty())
        throw MeshError(
            "(empty mesh spec): give a built-in name (sphere, torus, torus_knot, "
            "hand, square, wave, drape) or a mesh file path");
    // A built-in name wins unless a regular file of that exact name exists.
    std::error_code error;
    if (is_builtin_mesh_spec(spec) && !std::filesystem::is_regular_file(spec, error))
        return build_builtin_mesh(spec);
    return load_mesh_file(spec);
}

}  // namespace lucent
