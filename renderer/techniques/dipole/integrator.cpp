#include "renderer/techniques/dipole/integrator.h"

#include <algorithm>
#include <cmath>

namespace lucent::dipole {
namespace {

double longest_edge(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    return std::sqrt(std::max(
        {glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)}));
}

}  // namespace

ScatteringIntegrator::ScatteringIntegrator(const Mesh& mesh, double scale_mm,
                                           glm::dvec3 light_object,
                                           const Material& material,
                                           const IntegratorQuality& quality,
                                           const RayCaster* visibility)
    : dipole_(material), quality_(quality) {
    min_zr_ = 1e300;
    for (int ch = 0; ch < 3; ++ch)
        if (dipole_[ch].scatters() && dipole_[ch].albedo() > 0.0)
            min_zr_ = std::min(min_zr_, dipole_[ch].z_real()),
            max_sigma_tr_ = std::max(max_sigma_tr_, dipole_[ch].sigma_tr());
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::dvec3 a = glm::dvec3(mesh.positions[t.x]) * scale_mm,
                         b = glm::dvec3(mesh.positions[t.y]) * scale_mm,
                         c = glm::dvec3(mesh.positions[t.z]) * scale_mm;
        total_area_ += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    if (min_zr_ == 1e300 || mesh.triangles.empty()) return;  // nothing scatters: B = 0

    // Step 1: the cell edge h, raised until the cell count fits.
    const auto level_for = [&](double edge, double h) {
        int level = 0;
        while (edge > h && level < 12) edge *= 0.5, ++level;
        return level;
    };
    double h = quality.cell_size_over_zr * min_zr_;
    for (int attempt = 0; attempt < 64; ++attempt) {
        std::size_t count = 0;
        for (const glm::uvec3& t : mesh.triangles) {
            const double edge = longest_edge(glm::dvec3(mesh.positions[t.x]),
                                             glm::dvec3(mesh.positions[t.y]),
                                             glm::dvec3(mesh.positions[t.z])) *
                                scale_mm;
            count += std::size_t(1) << (2 * level_for(edge, h));
        }
        if (count <= quality.max_cells) break;
        h *= std::sqrt(2.0);
    }
    cell_size_ = h;

    // Step 2: cells with their irradiance E / Id = pi Ft(eta, N.L) max(N.L, 0) V (Eq. 4).
    const glm::dvec3 l = glm::normalize(light_object);
    const float ray_offset = 1e-4f * mesh.bounding_sphere().radius;
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[t.x]),
                                 glm::dvec3(mesh.positions[t.y]),
                                 glm::dvec3(mesh.positions[t.z])};
        const glm::dvec3 n[3] = {glm::dvec3(mesh.normals[t.x]),
                                 glm::dvec3(mesh.normals[t.y]),
                                 glm::dvec3(mesh.normals[t.z])};
        const glm::dvec3 geometric = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
        // Eq. 4's cosine from the flat facet (its vertex normals give only the side):
        // the same flux whichever way a shape is tessellated (scattering.h).
        const double mu = glm::dot(facet_normal(p[0], p[1], p[2], n[0] + n[1] + n[2]), l);
        if (!(mu > 0.0)) continue;  // unlit: no cells
        const int level = level_for(longest_edge(p[0], p[1], p[2]) * scale_mm, h);
        const int steps = 1 << level;
        // Uniform subdivision of the barycentric square into steps^2 sub-triangles.
        const auto corner = [&](int i, int j) {  // barycentric (1 - u - v, u, v)
            return glm::dvec2(double(i) / steps, double(j) / steps);
        };
        const auto emit = [&](glm::dvec2 q0, glm::dvec2 q1, glm::dvec2 q2) {
            const auto at = [&](glm::dvec2 q, const glm::dvec3* v) {
                return (1.0 - q.x - q.y) * v[0] + q.x * v[1] + q.y * v[2];
            };
            const glm::dvec2 g = (q0 + q1 + q2) / 3.0;
            Cell cell;
            cell.a = at(q0, p) * scale_mm;
            cell.b = at(q1, p) * scale_mm;
            cell.c = at(q2, p) * scale_mm;
            cell.centroid = (cell.a + cell.b + cell.c) / 3.0;
            cell.area = 0.5 * glm::length(glm::cross(cell.b - cell.a, cell.c - cell.a));
            if (!(cell.area > 0.0)) return;
            if (visibility) {
                const glm::dvec3 origin = at(g, p) + double(ray_offset) * l +
                                          double(ray_offset) *
                                              (glm::dot(geometric, l) >= 0 ? 1.0 : -1.0) *
                                              geometric;
                if (visibility->occluded(glm::vec3(origin), glm::vec3(l), 0.0f, 1e30f))
                    return;
            }
            cell.irradiance = kPi * fresnel_transmittance(material.eta, mu) * mu;
            if (cell.irradiance > 0.0) cells_.push_back(cell);
        };
        for (int j = 0; j < steps; ++j)
            for (int i = 0; i + j < steps; ++i) {
                emit(corner(i, j), corner(i + 1, j), corner(i, j + 1));
                if (i + j + 1 < steps)
                    emit(corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1));
            }
    }
    for (const Cell& cell : cells_) flux_ += cell.irradiance * cell.area;
    if (!cells_.empty()) build(0, int(cells_.size()), 0);
}

ScatteringIntegrator::~ScatteringIntegrator() = default;

int ScatteringIntegrator::build(int first, int count, int depth) {
    const int index = int(nodes_.size());
    nodes_.emplace_back();
    Node node;
    node.lo = glm::dvec3(1e300);
    node.hi = glm::dvec3(-1e300);
    node.centroid = glm::dvec3(0.0);
    for (int i = first; i < first + count; ++i) {
        const Cell& c = cells_[i];
        node.lo = glm::min(node.lo, glm::min(c.a, glm::min(c.b, c.c)));
        node.hi = glm::max(node.hi, glm::max(c.a, glm::max(c.b, c.c)));
        node.flux += c.irradiance * c.area;
        node.centroid += c.irradiance * c.area * c.centroid;
    }
    node.centroid /= node.flux;
    for (int i = first; i < first + count; ++i) {
        const Cell& c = cells_[i];
        const glm::dvec3 o = c.centroid - node.centroid;
        const glm::dvec3 ea = c.a - c.centroid, eb = c.b - c.centroid,
                         ec = c.c - c.centroid;
        // Each cell's offset plus its own spread (uniform triangle: (1/12) sum e e^T).
        node.spread += c.irradiance * c.area *
                       (glm::outerProduct(o, o) +
                        (glm::outerProduct(ea, ea) + glm::outerProduct(eb, eb) +
                         glm::outerProduct(ec, ec)) /
                            12.0);
    }
    const glm::dvec3 extent = node.hi - node.lo;
    node.size = std::max({extent.x, extent.y, extent.z});
    node.first = first;
    node.count = count;
    if (count > 8 && depth < 40) {
        // Split at the box centre into octants (partition in place).
        const glm::dvec3 mid = 0.5 * (node.lo + node.hi);
        auto begin = cells_.begin() + first, end = begin + count;
        const auto octant = [&](const Cell& c) {
            return (c.centroid.x > mid.x ? 1 : 0) | (c.centroid.y > mid.y ? 2 : 0) |
                   (c.centroid.z > mid.z ? 4 : 0);
        };
        std::stable_sort(begin, end, [&](const Cell& a, const Cell& b) {
            return octant(a) < octant(b);
        });
        int start = first, used = 0;
        for (int o = 0; o < 8; ++o) {
            int n = 0;
            while (start + n < first + count && octant(cells_[start + n]) == o) ++n;
            node.child[o] = -1;
            if (n > 0) {
                if (n == count) break;  // all in one octant (coincident centroids)
                node.child[o] = build(start, n, depth + 1);
                ++used;
            }
            start += n;
        }
        node.leaf = used == 0;
    }
    nodes_[index] = node;
    return index;
}

glm::dvec3 ScatteringIntegrator::refine(const glm::dvec3& a, const glm::dvec3& b,
                                        const glm::dvec3& c, double irradiance,
                                        const glm::dvec3& xo, int depth) const {
    const glm::dvec3 g = (a + b + c) / 3.0;
    const double d = glm::length(g - xo);
    if (depth >= 16 ||
        longest_edge(a, b, c) <= quality_.near_field_ratio * std::max(d, min_zr_)) {
        // The cell's own second moment: a uniform triangle has covariance
        // (1/12) sum (v_i - g)(v_i - g)^T.
        const double flux = irradiance * 0.5 * glm::length(glm::cross(b - a, c - a));
        const glm::dvec3 ea = a - g, eb = b - g, ec = c - g;
        const glm::dmat3 spread =
            (flux / 12.0) * (glm::outerProduct(ea, ea) + glm::outerProduct(eb, eb) +
                             glm::outerProduct(ec, ec));
        return expansion(flux, g, spread, xo);
    }
    const glm::dvec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    return refine(a, ab, ca, irradiance, xo, depth + 1) +
           refine(ab, b, bc, irradiance, xo, depth + 1) +
           refine(ca, bc, c, irradiance, xo, depth + 1) +
           refine(ab, bc, ca, irradiance, xo, depth + 1);
}

glm::dvec3 ScatteringIntegrator::expansion(double flux, const glm::dvec3& centroid,
                                           const glm::dmat3& spread,
                                           const glm::dvec3& xo) const {
    // Taylor expansion of f(|x - xo|) about the centroid to second order: the first-order
    // term vanishes (flux-weighted centroid), the second is 1/2 tr(H S) with the Hessian
    // of a radial function H = f'' u u^T + f'/d (I - u u^T), S the spread.
    const glm::dvec3 offset = centroid - xo;
    const double d = glm::length(offset);
    const double h = 1e-3 * std::max(d, min_zr_);
    const glm::dvec3 f0 = dipole_.rd(d);
    if (d < 2.0 * h) return flux * f0;  // at the centroid: the monopole
    const glm::dvec3 u = offset / d;
    const double radial = glm::dot(u, spread * u);
    const double trace = spread[0][0] + spread[1][1] + spread[2][2];
    const glm::dvec3 fp = dipole_.rd(d + h), fm = dipole_.rd(d - h);
    const glm::dvec3 first = (fp - fm) / (2.0 * h),
                     second = (fp - 2.0 * f0 + fm) / (h * h);
    return flux * f0 + 0.5 * (second * radial + first / d * (trace - radial));
}

glm::dvec3 ScatteringIntegrator::radiosity(glm::dvec3 xo) const {
    glm::dvec3 sum(0.0);
    if (nodes_.empty()) return sum;
    int stack[512];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        const double d = glm::length(node.centroid - xo);
        // Distance to the node's box: far-field acceptance needs xo outside it.
        const glm::dvec3 gap =
            glm::max(glm::max(node.lo - xo, xo - node.hi), glm::dvec3(0));
        const bool outside = glm::dot(gap, gap) > 0.0;
        // Far field: small against the distance and against the decay length 1/sigma_tr.
        if (outside && node.size < quality_.opening_angle * d &&
            node.size * max_sigma_tr_ < 2.0 * quality_.opening_angle) {
            sum += expansion(node.flux, node.centroid, node.spread, xo);
            continue;
        }
        if (node.leaf) {
            for (int i = node.first; i < node.first + node.count; ++i) {
                const Cell& c = cells_[i];
                sum += refine(c.a, c.b, c.c, c.irradiance, xo, 0);
            }
            continue;
        }
        for (int o = 0; o < 8; ++o)
            if (node.child[o] >= 0 && top < 512) stack[top++] = node.child[o];
    }
    return sum;
}

}  // namespace lucent::dipole
