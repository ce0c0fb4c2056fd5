// Per-vertex AO bake (thesis Eq. 3.5): AO = (1/N) sum_i V(p, w_i), V = 1 when the ray
// escapes. Directions: AoDirections (stratified, uniform over the hemisphere, shifted per
// vertex). Each vertex's rays go to Embree as one stream, on paired quads with denormals
// flushed (OcclusionCounter; each measured fastest by `lucent bench ao`). Each vertex's
// result depends only on its index, never on which thread bakes it.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <thread>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/cpu/ambient_occlusion_directions.h"
#include "renderer/cpu/embree_backend.h"
#include "renderer/cpu/occlusion_counter.h"

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

double thread_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

AoDirections::AoDirections(int rays) {
    if (rays < 1)
        throw std::invalid_argument("ao_rays: must be at least 1 (got " +
                                    std::to_string(rays) + ")");
    constexpr double kGolden = 0.6180339887498949;  // 1 / golden ratio
    cos_theta_base_.resize(static_cast<std::size_t>(rays));
    cos_sin_phi_.resize(static_cast<std::size_t>(rays));
    for (int i = 0; i < rays; ++i) {
        cos_theta_base_[i] = (i + 0.5) / rays;
        double v = i * kGolden;
        v -= std::floor(v);
        const double phi = 2.0 * std::numbers::pi * v;
        cos_sin_phi_[i] = {std::cos(phi), std::sin(phi)};
    }
}

void AoDirections::generate(std::size_t vertex, glm::vec3 n,
                            std::vector<glm::vec3>& out) const {
    glm::vec3 t, b;
    tangent_frame(n, t, b);
    const std::uint64_t h = mix(kSeed ^ mix(vertex));
    const double shift_u = unit_interval(h), shift_v = unit_interval(mix(h));
    // phi_i + 2 pi shift_v, by rotating the frame once.
    const double rotation = 2.0 * std::numbers::pi * shift_v;
    const glm::dvec3 td(t), bd(b), nd(n);
    const glm::dvec3 tr = std::cos(rotation) * td + std::sin(rotation) * bd;
    const glm::dvec3 br = -std::sin(rotation) * td + std::cos(rotation) * bd;
    out.resize(cos_sin_phi_.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        double u = cos_theta_base_[i] + shift_u;  // in [0, 2): wrap once
        if (u >= 1.0) u -= 1.0;
        // Uniform over solid angle: cos(theta) = 1 - u uniform in (0, 1] (u < 1, so
        // never exactly grazing); sin(theta) = sqrt(1 - cos^2) = sqrt(u (2 - u)).
        const double cos_theta = 1.0 - u;
        const double sin_theta = std::sqrt(u * (2.0 - u));
        const glm::dvec2 cs = cos_sin_phi_[i];
        out[i] = glm::vec3(sin_theta * (cs.x * tr + cs.y * br) + cos_theta * nd);
    }
}

std::vector<float> embree_bake_ambient_occlusion(const Mesh& mesh,
                                                 const AoBakeOptions& options) {
    const AoDirections lattice(options.rays);  // throws for rays < 1
    const std::size_t total = mesh.vertex_count();
    std::vector<float> result(total, 1.0f);
    if (total == 0 || mesh.triangles.empty()) {
        if (options.progress) options.progress(total, total);
        return result;  // nothing to occlude
    }
    const OcclusionCounter counter(mesh);
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
    const bool timed = options.timings != nullptr;

    std::atomic<std::size_t> next_chunk{0}, done{0};
    std::mutex timings_mutex;
    auto work = [&] {  // bakes one chunk; false when none is left
        const std::size_t first = next_chunk.fetch_add(1) * kChunk;
        if (first >= total) return false;
        const std::size_t last = std::min(total, first + kChunk);
        thread_local std::vector<glm::vec3> directions;
        double setup = 0.0, trace = 0.0;
        for (std::size_t v = first; v < last; ++v) {
            const double t0 = timed ? thread_cpu_seconds() : 0.0;
            lattice.generate(v, normals[v], directions);
            // Start just above the surface so the vertex's own triangles are not hit.
            const glm::vec3 origin = mesh.positions[v] + offset * normals[v];
            const double t1 = timed ? thread_cpu_seconds() : 0.0;
            result[v] =
                float(counter.count_escaping(origin, directions)) / float(options.rays);
            if (timed) {
                const double t2 = thread_cpu_seconds();
                setup += t1 - t0;
                trace += t2 - t1;
            }
        }
        if (timed) {
            std::lock_guard lock(timings_mutex);
            options.timings->setup_cpu_seconds += setup;
            options.timings->trace_cpu_seconds += trace;
        }
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
    if (timed) options.timings->rays += double(total) * options.rays;
    return result;
}

}  // namespace lucent
