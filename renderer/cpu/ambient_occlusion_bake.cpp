// Per-vertex AO bake (thesis Eq. 3.5): AO = (1/N) sum_i V(p, w_i), V = 1 when the ray
// escapes. Directions are uniform over the hemisphere around the vertex normal and
// stratified: a rank-1 lattice (N strata in cos(theta), golden-ratio steps in phi),
// shifted per vertex by a hash of its index (a Cranley-Patterson rotation, so
// neighbouring vertices do not share one pattern's bias). Each vertex's result depends
// only on its index, never on which thread bakes it.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/ambient_occlusion.h"
#include "cpu/ray_caster.h"

namespace lucent {

namespace {

constexpr std::uint64_t kSeed =
    0x6c75'6365'6e74'414full;       // fixed: bakes are reproducible
constexpr std::size_t kChunk = 64;  // vertices per work item

// SplitMix64 finaliser: a well-mixed 64-bit hash of the vertex index.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

double unit_interval(std::uint64_t bits) { return double(bits >> 11) * 0x1.0p-53; }

// Orthonormal basis around a unit normal (Duff et al. 2017, branch-free).
void tangent_frame(glm::vec3 n, glm::vec3& t, glm::vec3& b) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

float vertex_ambient_occlusion(const RayCaster& caster, const Mesh& mesh,
                               const std::vector<glm::vec3>& normals, std::size_t vertex,
                               int rays, float offset,
                               std::vector<glm::vec3>& directions) {
    const glm::vec3 n = normals[vertex];
    glm::vec3 t, b;
    tangent_frame(n, t, b);
    const std::uint64_t h = mix(kSeed ^ mix(vertex));
    const double shift_u = unit_interval(h), shift_v = unit_interval(mix(h));
    constexpr double kGolden = 0.6180339887498949;  // 1 / golden ratio
    directions.resize(static_cast<std::size_t>(rays));
    for (int i = 0; i < rays; ++i) {
        double u = (i + 0.5) / rays + shift_u;
        u -= std::floor(u);
        double v = i * kGolden + shift_v;
        v -= std::floor(v);
        // Uniform over solid angle: cos(theta) uniform in (0, 1] (never exactly grazing).
        const double cos_theta = 1.0 - u;
        const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
        const double phi = 2.0 * std::numbers::pi * v;
        directions[i] =
            glm::normalize(float(sin_theta * std::cos(phi)) * t +
                           float(sin_theta * std::sin(phi)) * b + float(cos_theta) * n);
    }
    // Start just above the surface so the vertex's own triangles are not hit.
    const glm::vec3 origin = mesh.positions[vertex] + offset * n;
    return float(caster.count_escaping(origin, directions)) / float(rays);
}

}  // namespace

std::vector<float> bake_ambient_occlusion(const Mesh& mesh,
                                          const AoBakeOptions& options) {
    if (options.rays < 1)
        throw std::invalid_argument("ao_rays: must be at least 1 (got " +
                                    std::to_string(options.rays) + ")");
    const std::size_t total = mesh.vertex_count();
    std::vector<float> result(total, 1.0f);
    if (total == 0 || mesh.triangles.empty()) {
        if (options.progress) options.progress(total, total);
        return result;  // nothing to occlude
    }
    const RayCaster caster(mesh);
    // Meshes from load_mesh() have unit normals; one assembled by hand may not.
    std::vector<glm::vec3> repaired;
    bool usable = mesh.normals.size() == total;
    for (std::size_t i = 0; usable && i < total; ++i)
        usable = std::abs(glm::length(mesh.normals[i]) - 1.0f) < 1e-3f;
    if (!usable) {
        Mesh copy = mesh;
        finalize_mesh(copy);
        repaired = std::move(copy.normals);
    }
    const std::vector<glm::vec3>& normals = usable ? mesh.normals : repaired;
    // Scale-aware offset: far above float noise at the mesh's size, far below its detail.
    const float offset = 1e-4f * std::max(mesh.bounding_sphere().radius, 1e-6f);

    std::atomic<std::size_t> next_chunk{0}, done{0};
    auto work = [&] {  // bakes one chunk; false when none is left
        const std::size_t first = next_chunk.fetch_add(1) * kChunk;
        if (first >= total) return false;
        const std::size_t last = std::min(total, first + kChunk);
        std::vector<glm::vec3> directions;
        for (std::size_t v = first; v < last; ++v)
            result[v] = vertex_ambient_occlusion(caster, mesh, normals, v, options.rays,
                                                 offset, directions);
        done.fetch_add(last - first);
        return true;
    };
    unsigned threads = options.threads != 0
                           ? options.threads
                           : std::max(1u, std::thread::hardware_concurrency());
    threads = static_cast<unsigned>(
        std::min<std::size_t>(threads, (total + kChunk - 1) / kChunk));
    std::vector<std::thread> workers;
    for (unsigned i = 1; i < threads; ++i)
        workers.emplace_back([&] {
            while (work()) {
            }
        });
    // The calling thread works too, reporting progress between its chunks.
    while (work())
        if (options.progress) options.progress(done.load(), total);
    for (std::thread& worker : workers) worker.join();
    if (options.progress) options.progress(total, total);
    return result;
}

}  // namespace lucent
