#pragma once
// Triangle meshes: built-in procedural shapes (so nothing needs files) and files loaded
// through Assimp, cleaned (degenerate triangles dropped, smooth normals generated when
// missing) and identified by a content hash.
#include <cstdint>
#include <glm/glm.hpp>
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
    std::string name;  // the spec it came from: "torus_knot:240k" or a path
    std::vector<glm::vec3> positions;   // object space
    std::vector<glm::vec3> normals;     // unit length, one per position
    std::vector<glm::uvec3> triangles;  // indices into positions; no degenerate ones
    // Texture coordinates, empty or one per position (files keep theirs; the sheets
    // `square`, `wave`, `drape` have them). Tangents come with them: xyz unit, along
    // dp/du made orthogonal to the normal, w = +-1 so that B = w * cross(N, T) points
    // along dp/dv.
    std::vector<glm::vec2> uvs;
    std::vector<glm::vec4> tangents;
    std::string content_hash;  // hex digest of positions + triangles (+ uvs when present)
    // True when the triangles bound a solid and face out of it (bounds_solid_facing_out;
    // set by finalize_mesh). Then from outside the nearest surface along any ray faces
    // the viewer and the next one faces away, so renderers may cull by facing instead of
    // peeling layers. False (the safe answer) for meshes never finalised.
    bool closed_facing_out = false;

    bool has_uvs() const { return !uvs.empty() && uvs.size() == positions.size(); }
    std::size_t face_count() const { return triangles.size(); }
    std::size_t vertex_count() const { return positions.size(); }
    // Contains every position; the smaller of the AABB-centred and Ritter spheres.
    BoundingSphere bounding_sphere() const;
};

// Builds a mesh from a spec: a built-in name with an optional face budget
// ("sphere", "torus_knot:240k", "hand:30000"), or a path to a file Assimp reads
// (OBJ, PLY, glTF, STL, OFF, ...). Throws MeshError. Defined in lucent_mesh_io
// (renderer/io/), so that the core links no importer.
Mesh load_mesh(const std::string& spec);

// The built-in procedural mesh names, for help text and error messages.
std::vector<std::string> builtin_mesh_names();

// Face budget of a built-in mesh when the spec gives none.
inline constexpr std::size_t kDefaultFaceBudget = 30000;

// 64-bit FNV-1a over the position bits and triangle indices (and the uv bits when `uvs`
// is not empty, so meshes without UVs keep their old hashes), as 16 hex digits.
std::string compute_content_hash(const std::vector<glm::vec3>& positions,
                                 const std::vector<glm::uvec3>& triangles,
                                 const std::vector<glm::vec2>& uvs = {});

// Per-vertex tangent frames from UVs: dp/du of each incident triangle summed (weighted by
// the triangle's area in uv space, i.e. solved per triangle), then Gram-Schmidt against
// the normal; w = sign of dot(cross(N, T), dp/dv). A vertex whose sum vanishes (zero-area
// uv triangles) gets any unit vector perpendicular to its normal, w = +1.
std::vector<glm::vec4> compute_tangents(const std::vector<glm::vec3>& positions,
                                        const std::vector<glm::vec3>& normals,
                                        const std::vector<glm::vec2>& uvs,
                                        const std::vector<glm::uvec3>& triangles);

// Unit per-vertex normals: incident face normals weighted by the corner angle (so the
// result does not depend on how a flat region is triangulated). A vertex whose weighted
// sum vanishes gets the normal of its first incident face; an unreferenced one +Z.
std::vector<glm::vec3> compute_smooth_normals(const std::vector<glm::vec3>& positions,
                                              const std::vector<glm::uvec3>& triangles);

// Whether `triangles` bound a solid and face out of it: with vertices at bit-identical
// positions merged (seams), every edge is shared by exactly two triangles that run along
// it in opposite directions (a closed, consistently wound surface), and the volume they
// enclose, counter-clockwise being the front, is positive. Along a ray from outside,
// crossings of such a surface then alternate entering (a front face) and leaving (a back
// face). Self-intersection is not checked (it costs far more and no mesh Lucent builds
// has it). O(F log F).
bool bounds_solid_facing_out(const std::vector<glm::vec3>& positions,
                             const std::vector<glm::uvec3>& triangles);

// Replaces non-finite or zero-length normals (computing smooth ones when `normals` is
// empty or the wrong size), normalises the rest, computes tangents when there are UVs
// (dropping UVs of the wrong count) and sets content_hash and closed_facing_out.
void finalize_mesh(Mesh& mesh);

}  // namespace lucent
