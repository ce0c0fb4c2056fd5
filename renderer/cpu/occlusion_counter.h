#pragma once
// How many of a fan of rays from one point escape a mesh: the AO bake's estimator (thesis
// Eq. 3.5), and nothing else, so its Embree scene is laid out for any-hit queries alone:
// triangles that share an edge are handed to Embree as one quad (the same two
// triangles, watertight in robust mode like RayCaster's), which halves the primitives
// and, stored with their vertices (bvh8.quad4v), traced the bake's rays 1.2x faster than
// the triangles on torus_knot:240k (6.97 -> 8.39 Mrays per CPU-second in one stream per
// vertex; `lucent bench ao` times both).
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent {

// How count_escaping() hands its rays to Embree. All give the same counts (the rays are
// the same); they differ in speed only (`lucent bench ao` times each).
enum class OcclusionQuery {
    single,   // rtcOccluded1 per ray
    packet8,  // rtcOccluded8 on consecutive groups of 8 rays
    stream,   // one rtcOccluded1M call for all the rays (Embree regroups them)
};

// Triangles as Embree quads (v0, v1, v2, v3), each the triangles (v0, v1, v3) and
// (v2, v3, v1): two triangles that share an edge, wound as in the mesh (the edge runs
// opposite ways in them), make one quad; a triangle without such a partner is (a, b, c,
// c), whose second triangle is degenerate and never hit. Every input triangle appears in
// exactly one quad, its vertices in their own cyclic order. Greedy, in triangle order.
struct PairedTriangles {
    std::vector<glm::uvec4> quads;
    std::size_t paired = 0;  // triangles that share a quad with another
};
PairedTriangles pair_triangles(const std::vector<glm::uvec3>& triangles);

enum class OcclusionScene {
    paired_quads,  // the counter's layout (fastest measured)
    triangles,     // RayCaster's layout, for `lucent bench ao` to compare
};

// Builds the Embree scene once (robust: rays through shared edges or vertices never slip
// through); count_escaping is const and thread-safe.
class OcclusionCounter {
public:
    // Throws std::invalid_argument for a triangle indexing past the positions and
    // std::runtime_error when Embree fails.
    explicit OcclusionCounter(const Mesh& mesh,
                              OcclusionScene layout = OcclusionScene::paired_quads);
    ~OcclusionCounter();
    OcclusionCounter(OcclusionCounter&&) noexcept;
    OcclusionCounter& operator=(OcclusionCounter&&) noexcept;

    // How many rays from `origin` along `directions` (unit) hit nothing with distance in
    // (t_min, inf). A non-finite origin counts every ray as escaping (it hits nothing).
    std::size_t count_escaping(glm::vec3 origin, const std::vector<glm::vec3>& directions,
                               float t_min = 0.0f,
                               OcclusionQuery query = OcclusionQuery::stream) const;

    std::size_t primitives() const;  // quads, or triangles
    std::size_t paired_triangles() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace lucent
