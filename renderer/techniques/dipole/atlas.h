#pragma once
// Texture space of the dipole technique (Chang et al. Sec. 2.2-3), GL-free:
//   - a surfel atlas: A x A texels, each an equal share of the surface area (mm^2) at a
//     stratified point of one triangle, sorted by 3D Morton code and written in 2D Morton
//     order, so it preserves area exactly and neighbouring texels are neighbours on the
//     surface (README.md says why this instead of a UV parameterisation);
//   - the mass pyramid of a texel field (2x2 box sums up to the 1x1 total Phi);
//   - the inverse-CDF descent through it (normalised by the four children, never a
//     zero-mass texel) and N stratified deterministic sample positions y_k = (k + xi)/N.
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent::dipole {

struct SurfaceAtlas {
    int resolution = 0;                    // A, a power of two
    std::vector<glm::vec4> position_area;  // A*A, row-major: xyz in mm, w = area mm^2
    std::vector<glm::vec4> normal;         // A*A: unit facet normal (facet_normal), w = 0
    double total_area = 0.0;               // mm^2, = sum of w
    std::string content_hash;              // of mesh hash, scale and resolution
};

// Every texel gets total_area / A^2: texel k sits at cumulative area (k + 1/2)/A^2 of
// the triangles in index order, and the n texels of one triangle at a Fibonacci lattice
// mapped area-uniformly onto it. `scale_mm` converts mesh units to mm. Throws
// std::invalid_argument for a resolution that is not a power of two in [1, 4096] or a
// mesh without area.
SurfaceAtlas build_surface_atlas(const Mesh& mesh, double scale_mm, int resolution);

// Morton code of a 2D texel (x bits at even positions, y at odd) and its inverse.
std::uint32_t morton2(std::uint32_t x, std::uint32_t y);
glm::uvec2 morton2_decode(std::uint32_t code);

// Box-sum pyramid of a square power-of-two field: levels[0] is the field, levels.back()
// the 1x1 total.
struct MassPyramid {
    std::vector<std::vector<double>> levels;
    std::vector<int> sizes;  // side of each level
    double total() const { return levels.back()[0]; }
};
MassPyramid build_mass_pyramid(const std::vector<double>& field, int resolution);

// The level-0 texel that the inverse CDF maps y in [0, 1) to: from the top, at each
// level the four children (Morton order: (0,0), (1,0), (0,1), (1,1)) are normalised by
// their own sum, the first child with cumulative share above y is taken (zero-mass
// children skipped, the last non-zero child absorbing rounding) and y rescaled to it.
// nullopt when the total mass is 0. Each texel is drawn with probability mass / total.
std::optional<glm::ivec2> descend(const MassPyramid& pyramid, double y);

// y_k = (k + xi) / N for k < N, xi = frac(0.5 + seed * golden ratio conjugate).
std::vector<double> stratified_positions(int count, int seed);
double stratification_offset(int seed);

}  // namespace lucent::dipole
