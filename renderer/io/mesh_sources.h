#pragma once
// Internal to lucent_mesh_io: reading mesh files (load_mesh() dispatches built-in names
// to core/mesh_builtin.h and the rest here).
#include <optional>
#include <string>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent {

// Reads a file through Assimp and cleans it. Throws MeshError "PATH: reason".
Mesh load_mesh_file(const std::string& path);

// A file's contents before cleaning (indices may be out of range, faces degenerate).
struct RawMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;  // empty, or one per position
    std::vector<glm::vec2> uvs;      // empty, or one per position (texture channel 0)
    std::vector<glm::uvec3> triangles;
    std::size_t faces_in_file = 0;
};
// A PLY file with a 'tristrips' element (which Assimp 5.2 misreads), strips turned into
// triangles; nullopt for any other file. Throws MeshError on a malformed one.
std::optional<RawMesh> read_ply_triangle_strips(const std::string& path);

}  // namespace lucent
