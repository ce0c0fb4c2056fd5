#pragma once
// The AO bake's ray directions (thesis Eq. 3.5, uniform over the hemisphere), shared by
// the bake and `lucent bench ao`, which times Embree alone on the very same rays.
//
// A rank-1 lattice of N points, (i + 1/2)/N in cos(theta) and golden-ratio steps in phi,
// shifted per vertex by a hash of its index (a Cranley-Patterson rotation, so
// neighbouring vertices do not share one pattern's bias). phi is periodic, so its shift
// is applied once per vertex by rotating the tangent frame instead of per ray: only the
// cos(theta) shift and one square root remain per ray.
#include <cstddef>
#include <glm/glm.hpp>
#include <vector>

namespace lucent {

class AoDirections {
public:
    // Throws std::invalid_argument for rays < 1.
    explicit AoDirections(int rays);
    int rays() const { return static_cast<int>(cos_sin_phi_.size()); }
    // The directions for vertex `vertex` with unit normal `normal` (all with
    // dot(direction, normal) > 0, never exactly grazing), into `out`. Depends only on
    // (vertex, normal, rays): never on the thread or on the order of calls.
    void generate(std::size_t vertex, glm::vec3 normal,
                  std::vector<glm::vec3>& out) const;

private:
    std::vector<double> cos_theta_base_;   // (i + 1/2) / N
    std::vector<glm::dvec2> cos_sin_phi_;  // of 2 pi frac(i / golden ratio)
};

}  // namespace lucent
