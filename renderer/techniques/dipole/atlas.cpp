#include "renderer/techniques/dipole/atlas.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "renderer/techniques/dipole/scattering.h"

namespace lucent::dipole {
namespace {

std::uint32_t spread_bits_2(std::uint32_t v) {  // 16 bits -> even positions
    v &= 0xffffu;
    v = (v | (v << 8)) & 0x00ff00ffu;
    v = (v | (v << 4)) & 0x0f0f0f0fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}
std::uint32_t compact_bits_2(std::uint32_t v) {
    v &= 0x55555555u;
    v = (v | (v >> 1)) & 0x33333333u;
    v = (v | (v >> 2)) & 0x0f0f0f0fu;
    v = (v | (v >> 4)) & 0x00ff00ffu;
    v = (v | (v >> 8)) & 0x0000ffffu;
    return v;
}
std::uint64_t spread_bits_3(std::uint64_t v) {  // 21 bits -> every third position
    v &= 0x1fffffull;
    v = (v | (v << 32)) & 0x1f00000000ffffull;
    v = (v | (v << 16)) & 0x1f0000ff0000ffull;
    v = (v | (v << 8)) & 0x100f00f00f00f00full;
    v = (v | (v << 4)) & 0x10c30c30c30c30c3ull;
    v = (v | (v << 2)) & 0x1249249249249249ull;
    return v;
}

constexpr double kGoldenConjugate = 0.6180339887498949;

}  // namespace

std::uint32_t morton2(std::uint32_t x, std::uint32_t y) {
    return spread_bits_2(x) | (spread_bits_2(y) << 1);
}
glm::uvec2 morton2_decode(std::uint32_t code) {
    return {compact_bits_2(code), compact_bits_2(code >> 1)};
}

SurfaceAtlas build_surface_atlas(const Mesh& mesh, double scale_mm, int resolution) {
    if (resolution < 1 || resolution > 4096 || (resolution & (resolution - 1)) != 0)
        throw std::invalid_argument("atlas resolution " + std::to_string(resolution) +
                                    " is not a power of two in [1, 4096]");
    const std::size_t faces = mesh.triangles.size();
    // Step 1: cumulative triangle areas (mm^2).
    std::vector<double> cumulative(faces + 1, 0.0);
    for (std::size_t j = 0; j < faces; ++j) {
        const glm::uvec3 t = mesh.triangles[j];
        const glm::dvec3 a = glm::dvec3(mesh.positions[t.x]) * scale_mm,
                         b = glm::dvec3(mesh.positions[t.y]) * scale_mm,
                         c = glm::dvec3(mesh.positions[t.z]) * scale_mm;
        cumulative[j + 1] = cumulative[j] + 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    const double total = cumulative.back();
    if (!(total > 0.0) || !std::isfinite(total))
        throw std::invalid_argument(mesh.name + ": no surface area for the atlas");
    const std::size_t texels = std::size_t(resolution) * resolution;
    const double share = total / double(texels);

    // Step 2: texel k at cumulative area (k + 1/2) share; the run of texels of one
    // triangle is placed on a Fibonacci lattice mapped area-uniformly to the triangle.
    struct Surfel {
        glm::dvec3 position, normal;
        std::uint64_t key;
    };
    std::vector<Surfel> surfels(texels);
    glm::dvec3 lo(1e300), hi(-1e300);
    std::size_t k = 0;
    for (std::size_t j = 0; j < faces && k < texels; ++j) {
        std::size_t end = k;
        while (end < texels && (double(end) + 0.5) * share < cumulative[j + 1]) ++end;
        if (j + 1 == faces) end = texels;  // rounding: the last triangle takes the rest
        const std::size_t n = end - k;
        const glm::uvec3 t = mesh.triangles[j];
        // The facet's normal, on its vertex normals' side: the irradiance pass's cosine
        // and shadow offset, as the CPU reference (scattering.h facet_normal).
        const glm::dvec3 normal =
            facet_normal(glm::dvec3(mesh.positions[t.x]), glm::dvec3(mesh.positions[t.y]),
                         glm::dvec3(mesh.positions[t.z]),
                         glm::dvec3(mesh.normals[t.x]) + glm::dvec3(mesh.normals[t.y]) +
                             glm::dvec3(mesh.normals[t.z]));
        for (std::size_t i = 0; i < n; ++i, ++k) {
            const double u = (double(i) + 0.5) / double(n);
            double v = std::fmod(0.5 + double(i) * kGoldenConjugate, 1.0);
            const double su = std::sqrt(u);
            const double w0 = 1.0 - su, w1 = su * (1.0 - v), w2 = su * v;
            Surfel& s = surfels[k];
            s.position = (w0 * glm::dvec3(mesh.positions[t.x]) +
                          w1 * glm::dvec3(mesh.positions[t.y]) +
                          w2 * glm::dvec3(mesh.positions[t.z])) *
                         scale_mm;
            s.normal = normal;
            lo = glm::min(lo, s.position);
            hi = glm::max(hi, s.position);
        }
    }
    // Step 3: sort by 3D Morton code, write along the 2D Morton curve.
    const glm::dvec3 extent = glm::max(hi - lo, glm::dvec3(1e-30));
    const double cell = std::max({extent.x, extent.y, extent.z}) / double((1 << 21) - 1);
    for (Surfel& s : surfels) {
        const glm::dvec3 q = (s.position - lo) / cell;
        s.key = spread_bits_3(std::uint64_t(q.x)) |
                (spread_bits_3(std::uint64_t(q.y)) << 1) |
                (spread_bits_3(std::uint64_t(q.z)) << 2);
    }
    std::stable_sort(surfels.begin(), surfels.end(),
                     [](const Surfel& a, const Surfel& b) { return a.key < b.key; });
    SurfaceAtlas atlas;
    atlas.resolution = resolution;
    atlas.total_area = total;
    atlas.position_area.resize(texels);
    atlas.normal.resize(texels);
    for (std::size_t m = 0; m < texels; ++m) {
        const glm::uvec2 xy = morton2_decode(std::uint32_t(m));
        const std::size_t index = std::size_t(xy.y) * resolution + xy.x;
        atlas.position_area[index] =
            glm::vec4(glm::vec3(surfels[m].position), float(share));
        atlas.normal[index] = glm::vec4(glm::vec3(surfels[m].normal), 0.0f);
    }
    atlas.content_hash = mesh.content_hash + "-s" + std::to_string(scale_mm) + "-a" +
                         std::to_string(resolution);
    return atlas;
}

MassPyramid build_mass_pyramid(const std::vector<double>& field, int resolution) {
    if (resolution < 1 || (resolution & (resolution - 1)) != 0 ||
        field.size() != std::size_t(resolution) * resolution)
        throw std::invalid_argument("mass pyramid: field is not a square power of two");
    MassPyramid p;
    p.levels.push_back(field);
    p.sizes.push_back(resolution);
    for (int size = resolution / 2; size >= 1; size /= 2) {
        const std::vector<double>& below = p.levels.back();
        const int wide = size * 2;
        std::vector<double> level(std::size_t(size) * size);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                level[std::size_t(y) * size + x] =
                    below[std::size_t(2 * y) * wide + 2 * x] +
                    below[std::size_t(2 * y) * wide + 2 * x + 1] +
                    below[std::size_t(2 * y + 1) * wide + 2 * x] +
                    below[std::size_t(2 * y + 1) * wide + 2 * x + 1];
        p.levels.push_back(std::move(level));
        p.sizes.push_back(size);
    }
    return p;
}

std::optional<glm::ivec2> descend(const MassPyramid& pyramid, double y) {
    if (!(pyramid.total() > 0.0)) return std::nullopt;
    y = std::clamp(y, 0.0, std::nextafter(1.0, 0.0));
    glm::ivec2 at(0);
    for (int level = int(pyramid.levels.size()) - 2; level >= 0; --level) {
        const int size = pyramid.sizes[level];
        const std::vector<double>& m = pyramid.levels[level];
        double child[4];
        double sum = 0.0;
        int last_nonzero = -1;
        for (int q = 0; q < 4; ++q) {
            const int cx = 2 * at.x + (q & 1), cy = 2 * at.y + (q >> 1);
            child[q] = m[std::size_t(cy) * size + cx];
            sum += child[q];
            if (child[q] > 0.0) last_nonzero = q;
        }
        if (last_nonzero < 0) return std::nullopt;  // unreachable: parent mass > 0
        const double target = y * sum;
        double before = 0.0;
        int pick = last_nonzero;
        for (int q = 0; q < 4; ++q) {
            if (child[q] > 0.0 && target < before + child[q]) {
                pick = q;
                break;
            }
            before += child[q];
        }
        if (pick == last_nonzero)
            before = sum - child[pick];  // the same cumulative, also after rounding
        y = std::clamp((target - before) / child[pick], 0.0, std::nextafter(1.0, 0.0));
        at = {2 * at.x + (pick & 1), 2 * at.y + (pick >> 1)};
    }
    return at;
}

double stratification_offset(int seed) {
    return std::fmod(0.5 + double(seed) * kGoldenConjugate, 1.0);
}

std::vector<double> stratified_positions(int count, int seed) {
    const double xi = stratification_offset(seed);
    std::vector<double> y(std::max(count, 0));
    for (int k = 0; k < count; ++k) y[k] = (double(k) + xi) / double(count);
    return y;
}

}  // namespace lucent::dipole
