// Mesh helpers shared by the built-in shapes and the file loader: bounding sphere,
// content hash and smooth normals (load_mesh() itself is in renderer/io).
#include "renderer/core/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unordered_map>

#include "common/content_hash.h"

namespace lucent {

namespace {

// Largest distance from `centre` to any position, computed in double precision and
// nudged up one part in 1e6 so float rounding never leaves a vertex outside.
float enclosing_radius(const std::vector<glm::vec3>& positions, glm::dvec3 centre) {
    double max_squared = 0.0;
    for (const glm::vec3& p : positions) {
        const glm::dvec3 d = glm::dvec3(p) - centre;
        max_squared = std::max(max_squared, glm::dot(d, d));
    }
    return static_cast<float>(std::sqrt(max_squared) * (1.0 + 1e-6));
}

// Ritter's approximate minimal sphere: start from two far-apart points, then grow.
glm::dvec3 ritter_centre(const std::vector<glm::vec3>& positions) {
    auto farthest_from = [&](glm::dvec3 from) {
        glm::dvec3 best = positions.front();
        double best_d = -1.0;
        for (const glm::vec3& p : positions) {
            const double d = glm::dot(glm::dvec3(p) - from, glm::dvec3(p) - from);
            if (d > best_d) best_d = d, best = p;
        }
        return best;
    };
    const glm::dvec3 a = farthest_from(positions.front());
    const glm::dvec3 b = farthest_from(a);
    glm::dvec3 centre = 0.5 * (a + b);
    double radius = 0.5 * glm::length(b - a);
    for (const glm::vec3& p : positions) {
        const double d = glm::length(glm::dvec3(p) - centre);
        if (d > radius) {
            const double grown = 0.5 * (radius + d);
            centre += (d - grown) / d * (glm::dvec3(p) - centre);
            radius = grown;
        }
    }
    return centre;
}

}  // namespace

BoundingSphere Mesh::bounding_sphere() const {
    if (positions.empty()) return {};
    glm::dvec3 lo(positions.front()), hi(positions.front());
    for (const glm::vec3& p : positions) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    const glm::dvec3 box_centre = 0.5 * (lo + hi);
    const glm::dvec3 ritter = ritter_centre(positions);
    const float box_radius = enclosing_radius(positions, box_centre);
    const float ritter_radius = enclosing_radius(positions, ritter);
    if (box_radius <= ritter_radius) return {glm::vec3(box_centre), box_radius};
    return {glm::vec3(ritter), ritter_radius};
}

std::string compute_content_hash(const std::vector<glm::vec3>& positions,
                                 const std::vector<glm::uvec3>& triangles,
                                 const std::vector<glm::vec2>& uvs) {
    common::ContentHash hash;
    // Counts first, so (positions, triangles) splits cannot collide by concatenation.
    hash.word(static_cast<std::uint32_t>(positions.size()));
    hash.word(static_cast<std::uint32_t>(triangles.size()));
    for (const glm::vec3& p : positions)
        for (int k = 0; k < 3; ++k) hash.float_bits(p[k]);  // -0 and +0 hash alike
    for (const glm::uvec3& t : triangles)
        for (int k = 0; k < 3; ++k) hash.word(t[k]);
    if (!uvs.empty()) {
        hash.word(static_cast<std::uint32_t>(uvs.size()));
        for (const glm::vec2& uv : uvs)
            for (int k = 0; k < 2; ++k) hash.float_bits(uv[k]);
    }
    return hash.hex();
}

std::vector<glm::vec3> compute_smooth_normals(const std::vector<glm::vec3>& positions,
                                              const std::vector<glm::uvec3>& triangles) {
    std::vector<glm::dvec3> sums(positions.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> fallback(positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& t : triangles) {
        const glm::dvec3 p[3] = {positions[t.x], positions[t.y], positions[t.z]};
        const glm::dvec3 face = glm::cross(p[1] - p[0], p[2] - p[0]);
        const double face_length = glm::length(face);
        if (!(face_length > 0.0)) continue;
        const glm::dvec3 unit = face / face_length;
        for (int corner = 0; corner < 3; ++corner) {
            const glm::dvec3 e1 = p[(corner + 1) % 3] - p[corner];
            const glm::dvec3 e2 = p[(corner + 2) % 3] - p[corner];
            const double angle =
                std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
            sums[t[corner]] += angle * unit;
            if (fallback[t[corner]] == glm::dvec3(0.0)) fallback[t[corner]] = unit;
        }
    }
    std::vector<glm::vec3> normals(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const double length = glm::length(sums[i]);
        if (length > 1e-12)
            normals[i] = glm::vec3(sums[i] / length);
        else if (fallback[i] != glm::dvec3(0.0))
            normals[i] = glm::vec3(fallback[i]);
        else
            normals[i] = glm::vec3(0.0f, 0.0f, 1.0f);
    }
    return normals;
}

std::vector<glm::vec4> compute_tangents(const std::vector<glm::vec3>& positions,
                                        const std::vector<glm::vec3>& normals,
                                        const std::vector<glm::vec2>& uvs,
                                        const std::vector<glm::uvec3>& triangles) {
    std::vector<glm::dvec3> du(positions.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> dv(positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& t : triangles) {
        const glm::dvec3 e1 = glm::dvec3(positions[t.y]) - glm::dvec3(positions[t.x]);
        const glm::dvec3 e2 = glm::dvec3(positions[t.z]) - glm::dvec3(positions[t.x]);
        const glm::dvec2 s1 = glm::dvec2(uvs[t.y]) - glm::dvec2(uvs[t.x]);
        const glm::dvec2 s2 = glm::dvec2(uvs[t.z]) - glm::dvec2(uvs[t.x]);
        // Solve [e1 e2] = [dp/du dp/dv] [s1 s2]; scaled by det so that large uv
        // triangles weigh more and a zero-area one adds nothing.
        const double det = s1.x * s2.y - s2.x * s1.y;
        if (!std::isfinite(det) || det == 0.0) continue;
        const double sign = det > 0.0 ? 1.0 : -1.0;
        const glm::dvec3 tu = (e1 * s2.y - e2 * s1.y) * sign;
        const glm::dvec3 tv = (e2 * s1.x - e1 * s2.x) * sign;
        for (int k = 0; k < 3; ++k) du[t[k]] += tu, dv[t[k]] += tv;
    }
    std::vector<glm::vec4> tangents(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const glm::dvec3 n = glm::dvec3(normals[i]);
        glm::dvec3 t = du[i] - n * glm::dot(n, du[i]);
        double length = glm::length(t);
        if (!(length > 1e-12 * (glm::length(du[i]) + 1e-300))) {
            // Any unit vector perpendicular to n.
            t = std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0))
                                    : glm::cross(n, glm::dvec3(0, 1, 0));
            length = glm::length(t);
        }
        t /= length;
        const double w = glm::dot(glm::cross(n, t), dv[i]) < 0.0 ? -1.0 : 1.0;
        tangents[i] = glm::vec4(glm::vec3(t), static_cast<float>(w));
    }
    return tangents;
}

bool bounds_solid_facing_out(const std::vector<glm::vec3>& positions,
                             const std::vector<glm::uvec3>& triangles) {
    if (triangles.empty()) return false;
    // Merge vertices at bit-identical positions, so a seam (vertices split for their
    // normals or UVs) does not count as a boundary: the rasteriser sees one edge there.
    struct PositionBits {
        std::size_t operator()(const glm::vec3& p) const {
            std::uint32_t bits[3];
            std::memcpy(bits, &p[0], sizeof bits);
            return (std::size_t(bits[0]) * 0x9e3779b1u) ^ (std::size_t(bits[1]) << 21) ^
                   (std::size_t(bits[2]) * 0x85ebca6bu);
        }
    };
    struct SameBits {
        bool operator()(const glm::vec3& a, const glm::vec3& b) const {
            return std::memcmp(&a[0], &b[0], sizeof(glm::vec3)) == 0;
        }
    };
    std::unordered_map<glm::vec3, std::uint32_t, PositionBits, SameBits> first_at;
    first_at.reserve(positions.size());
    std::vector<std::uint32_t> merged(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i)
        merged[i] = first_at.emplace(positions[i], std::uint32_t(i)).first->second;

    // Each edge as its undirected key with the direction in the lowest bit, sorted once:
    // a closed, consistently wound surface lists every key exactly twice, once each way.
    if (positions.size() >= (std::size_t(1) << 31)) return false;  // keys need 62 bits
    std::vector<std::uint64_t> edges;
    edges.reserve(3 * triangles.size());
    double six_volume = 0.0;
    for (const glm::uvec3& t : triangles) {
        if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size())
            return false;
        const std::uint32_t v[3] = {merged[t.x], merged[t.y], merged[t.z]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) return false;  // collapsed
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t from = v[k], to = v[(k + 1) % 3];
            const std::uint64_t key =
                std::uint64_t(std::min(from, to)) << 31 | std::max(from, to);
            edges.push_back(key << 1 | (from < to ? 0u : 1u));
        }
        // Divergence theorem: 6 V = sum over faces of p0 . (p1 x p2).
        const glm::dvec3 p0(positions[t.x]), p1(positions[t.y]), p2(positions[t.z]);
        six_volume += glm::dot(p0, glm::cross(p1, p2));
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i < edges.size(); i += 2)
        if (i + 1 == edges.size() || (edges[i] & 1u) != 0 ||
            edges[i + 1] != (edges[i] | 1u) ||
            (i + 2 < edges.size() && edges[i + 2] >> 1 == edges[i] >> 1))
            return false;
    return six_volume > 0.0 && std::isfinite(six_volume);
}

void finalize_mesh(Mesh& mesh) {
    if (mesh.normals.size() != mesh.positions.size())
        mesh.normals = compute_smooth_normals(mesh.positions, mesh.triangles);
    std::vector<glm::vec3> smooth;  // computed only if some normal needs replacing
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        glm::vec3& n = mesh.normals[i];
        const float length = glm::length(n);
        if (std::isfinite(length) && length > 1e-12f) {
            n /= length;
            continue;
        }
        if (smooth.empty())
            smooth = compute_smooth_normals(mesh.positions, mesh.triangles);
        n = smooth[i];
    }
    if (mesh.uvs.size() != mesh.positions.size()) mesh.uvs.clear();
    if (mesh.uvs.empty())
        mesh.tangents.clear();
    else if (mesh.tangents.size() != mesh.positions.size())
        mesh.tangents =
            compute_tangents(mesh.positions, mesh.normals, mesh.uvs, mesh.triangles);
    mesh.content_hash = compute_content_hash(mesh.positions, mesh.triangles, mesh.uvs);
    mesh.closed_facing_out = bounds_solid_facing_out(mesh.positions, mesh.triangles);
}

}  // namespace lucent
