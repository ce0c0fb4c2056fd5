#pragma once
// Ray casting over a Mesh for the CPU reference renderers (the AO bake counts escaping
// rays with cpu/occlusion_counter.h). GL-free and Embree-free: the queries go to the CPU
// backend (core/cpu_backend.h), Embree in every program that renders.
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent {

struct RayHit {
    float distance = 0.0f;             // along the (normalised) ray direction
    unsigned triangle = 0;             // index into Mesh::triangles
    glm::vec2 barycentric{0.0f};       // Embree's (u, v) for vertices 1 and 2
    glm::vec3 geometric_normal{0.0f};  // unit, as wound (counter-clockwise = front)
};

class RayQueries;  // core/cpu_backend.h

// Builds an Embree BVH once (robust mode: rays through shared edges or vertices never
// slip between triangles); all queries are const and thread-safe. Directions need not
// be normalised; a zero or non-finite direction or origin hits nothing.
class RayCaster {
public:
    explicit RayCaster(const Mesh& mesh);
    ~RayCaster();
    RayCaster(RayCaster&&) noexcept;
    RayCaster& operator=(RayCaster&&) noexcept;

    // Nearest hit with distance in (t_min, t_max), if any.
    std::optional<RayHit> first_hit(glm::vec3 origin, glm::vec3 direction,
                                    float t_min = 0.0f, float t_max = 1e30f) const;
    // Up to `max_hits` successive surface crossings along the ray, nearest first (depth
    // layers). Each next search starts layer_epsilon() beyond the previous hit, so one
    // surface is never reported twice (e.g. a ray through an edge shared by two
    // triangles); surfaces closer together than that merge into one layer.
    std::vector<RayHit> hits(glm::vec3 origin, glm::vec3 direction, int max_hits) const;
    // True when anything is hit with distance in (t_min, t_max).
    bool occluded(glm::vec3 origin, glm::vec3 direction, float t_min, float t_max) const;

    // 1e-5 of the mesh's bounding-sphere radius: the gap between successive layers.
    float layer_epsilon() const;

private:
    std::unique_ptr<RayQueries> queries_;
    float epsilon_ = 0.0f;
};

}  // namespace lucent
