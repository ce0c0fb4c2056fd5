// Per-texel records (Sec. 3.4) and their pyramid of averages.
#include <algorithm>

#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {
namespace {

TexelRecord zero_like(const TexelRecord& r) {
    TexelRecord z;
    for (int d = 0; d < 4; ++d) z.bins[d].assign(r.bins[d].size(), 0.0);
    return z;
}

void accumulate(TexelRecord& sum, const TexelRecord& r, double weight) {
    sum.walls += weight * r.walls;
    sum.triangles += weight * r.triangles;
    sum.opaque += weight * r.opaque;
    sum.premultiplied += weight * r.premultiplied;
    for (int d = 0; d < 4; ++d)
        for (std::size_t k = 0; k < r.bins[d].size(); ++k)
            sum.bins[d][k] += weight * r.bins[d][k];
}

}  // namespace

std::vector<TexelRecord> level0_records(const TexelGrid& g, int bins) {
    std::vector<TexelRecord> records(std::size_t(g.width) * g.height);
    // Rows and columns that hold an opaque texel at all (a run that never meets one goes
    // in no bin).
    std::vector<bool> row_has(g.height, false), column_has(g.width, false);
    for (int j = 0; j < g.height; ++j)
        for (int i = 0; i < g.width; ++i)
            if (g.at(i, j)) row_has[j] = column_has[i] = true;
    const glm::ivec2 step[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};  // R, L, U, D
    for (int j = 0; j < g.height; ++j)
        for (int i = 0; i < g.width; ++i) {
            TexelRecord& r = records[std::size_t(j) * g.width + i];
            if (bins > 1)
                for (auto& b : r.bins) b.assign(std::size_t(bins), 0.0);
            if (g.at(i, j)) {
                r.opaque = 1.0;
                r.premultiplied = glm::dvec3(g.colour_at(i, j));
                continue;
            }
            const auto b = [&](int di, int dj) {
                return g.at(i + di, j + dj) ? 1.0 : 0.0;
            };
            // Walls in Algorithm 3.1's order: top, left, bottom, right.
            r.walls = {b(0, 1), b(-1, 0), b(0, -1), b(1, 0)};
            // Triangles (TR, TL, BL, BR): the diagonal neighbour's wall seen through each
            // transparent side neighbour, 0..2 (README: derivation).
            const glm::ivec2 diagonal[4] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
            for (int k = 0; k < 4; ++k) {
                const int sx = diagonal[k].x, sy = diagonal[k].y;
                r.triangles[k] = b(sx, sy) * ((1.0 - b(sx, 0)) + (1.0 - b(0, sy)));
            }
            if (bins <= 1) continue;
            for (int d = 0; d < 4; ++d) {
                const bool any = d < 2 ? row_has[j] : column_has[i];
                if (!any) continue;
                int e = bins - 1;  // e >= K - 1 unless an opaque texel comes sooner
                for (int m = 1; m < bins; ++m)
                    if (g.at(i + m * step[d].x, j + m * step[d].y)) {
                        e = m - 1;
                        break;
                    }
                r.bins[d][std::size_t(e)] = 1.0;
            }
        }
    return records;
}

RecordPyramid build_pyramid(const TexelGrid& grid, int bins) {
    RecordPyramid pyramid;
    const glm::ivec3 base(grid.width, grid.height, 1);
    const int levels = full_mip_levels(base, false);
    pyramid.sizes.push_back({grid.width, grid.height});
    pyramid.levels.push_back(level0_records(grid, bins));
    for (int l = 1; l < levels; ++l) {
        const glm::ivec2 above = pyramid.sizes.back();
        const glm::ivec2 size = glm::ivec2(mip_size(base, l, false));
        const auto& src = pyramid.levels.back();
        std::vector<TexelRecord> level(std::size_t(size.x) * size.y,
                                       zero_like(src.front()));
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) {
                // 2x2 footprint, widened to the last row / column of the level above
                // (3 when it is odd), exactly as gl/shaders/box_mip.frag.
                const int x0 = std::min(2 * x, above.x - 1),
                          y0 = std::min(2 * y, above.y - 1);
                const int x1 = x == size.x - 1 ? above.x : std::min(2 * x + 2, above.x);
                const int y1 = y == size.y - 1 ? above.y : std::min(2 * y + 2, above.y);
                const double weight = 1.0 / double((x1 - x0) * (y1 - y0));
                TexelRecord& out = level[std::size_t(y) * size.x + x];
                for (int yy = y0; yy < y1; ++yy)
                    for (int xx = x0; xx < x1; ++xx)
                        accumulate(out, src[std::size_t(yy) * above.x + xx], weight);
            }
        pyramid.sizes.push_back(size);
        pyramid.levels.push_back(std::move(level));
    }
    return pyramid;
}

}  // namespace lucent::thick_texture
