#pragma once
// Triangle meshes: built-in procedural shapes (so nothing needs files) and files loaded
// through Assimp, cleaned (degenerate triangles dropped, smooth normals generated when
// missing) and identified by a content hash.
#include <glm/glm.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace lucent {

// Thrown for a mesh that cannot be loaded or built; what() is one line naming the file
// (or built-in spec) and the reason, e.g. "bunny.obj: Assimp: Unable to open file".
class MeshError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct BoundingSphere {
    glm::vec3 centre{0.0f};
    float radius = 0.0f;
    float diameter() const { return 2.0f * radius; }
};

struct Mesh {
    std::string name;                   // the spec it came from: "torus_knot:240k" or a path
    std::vector<glm::vec3> positions;   // object space
    std::vector<glm::vec3> normals;     // unit length, one per position
    std::vector<glm::uvec3> triangles;  // indices into positions; no degenerate ones
    std::string content_hash;           // hex digest of positions + triangles

    std::size_t face_count() const { return triangles.size(); }
    std::size_t vertex_count() const { return positions.size(); }
    BoundingSphere bounding_sphere() const;
};

// Builds a mesh from a spec: a built-in name with an optional face budget
// ("sphere", "torus_knot:240k", "hand:30000"), or a path to a file Assimp reads
// (OBJ, PLY, glTF, STL, OFF, ...). Throws MeshError.
Mesh load_mesh(const std::string& spec);

// The built-in procedural mesh names, for help text and error messages.
std::vector<std::string> builtin_mesh_names();

}  // namespace lucent
