// The ground truth's per-ray test (Sec. 4.2): a 2D Amanatides-Woo walk over the texel
// grid along the projection of the scaled ray; the first opaque texel entered before the
// bottom of the slab is a wall hit.
#include <cmath>
#include <limits>

#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {

SlabHit trace_slab(const TexelGrid& grid, glm::dvec2 p, glm::dvec2 r, glm::ivec2& texel,
                   int* steps) {
    glm::ivec2 cell(int(std::floor(p.x)), int(std::floor(p.y)));
    texel = cell;
    if (steps) *steps = 0;
    if (grid.at(cell.x, cell.y)) return SlabHit::top;
    const double inf = std::numeric_limits<double>::infinity();
    // Parameter s in [0, 1] along p + s r; next boundary crossing per axis.
    glm::ivec2 step(r.x > 0 ? 1 : -1, r.y > 0 ? 1 : -1);
    glm::dvec2 next(inf), delta(inf);
    if (r.x != 0.0) {
        delta.x = 1.0 / std::abs(r.x);
        next.x = (r.x > 0 ? (cell.x + 1.0 - p.x) : (p.x - cell.x)) * delta.x;
    }
    if (r.y != 0.0) {
        delta.y = 1.0 / std::abs(r.y);
        next.y = (r.y > 0 ? (cell.y + 1.0 - p.y) : (p.y - cell.y)) * delta.y;
    }
    // A walk longer than the tile in both directions only repeats it.
    const int limit = 4 * (grid.width + grid.height) + 8;
    for (int n = 0; n < limit; ++n) {
        if (next.x > 1.0 && next.y > 1.0) return SlabHit::through;
        if (next.x <= next.y) {
            cell.x += step.x;
            next.x += delta.x;
        } else {
            cell.y += step.y;
            next.y += delta.y;
        }
        if (steps) *steps = n + 1;
        if (grid.at(cell.x, cell.y)) {
            texel = cell;
            return SlabHit::wall;
        }
    }
    return SlabHit::through;
}

SlabHit trace_slab(const TexelGrid& grid, glm::dvec2 p, glm::dvec2 r, int* steps) {
    glm::ivec2 texel;
    return trace_slab(grid, p, r, texel, steps);
}

Fractions exact_fractions(const TexelGrid& grid, glm::dvec2 r, int s) {
    std::size_t top = 0, wall = 0, through = 0;
    for (int j = 0; j < grid.height; ++j)
        for (int i = 0; i < grid.width; ++i)
            for (int b = 0; b < s; ++b)
                for (int a = 0; a < s; ++a) {
                    // The y offset keeps samples off the texel diagonals, where the
                    // walk's tie-breaking (not the geometry) would decide.
                    const glm::dvec2 p(i + (a + 0.5) / s, j + (b + 0.5 + 0.1234) / s);
                    switch (trace_slab(grid, p, r)) {
                        case SlabHit::top:
                            ++top;
                            break;
                        case SlabHit::wall:
                            ++wall;
                            break;
                        case SlabHit::through:
                            ++through;
                            break;
                    }
                }
    const double n = double(top + wall + through);
    return {top / n, wall / n, through / n};
}

}  // namespace lucent::thick_texture
