#include "renderer/techniques/path/slab.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "renderer/techniques/path/walk.h"

namespace lucent::path {
namespace {

// The slab 0 <= z <= depth (optical units: sigma_t = 1), lit from z < 0, its outward
// normals -z at the top and +z at the bottom. Outside there is nothing to meet again.
struct SlabBoundary {
    double depth;
    double spawn_offset() const { return 0.0; }  // planes: exact positions
    std::optional<BoundaryHit> nearest(glm::dvec3 origin, glm::dvec3 direction,
                                       bool inside, double t_max) const {
        const std::optional<BoundaryHit> hit = plane_ahead(origin, direction, inside);
        if (hit && hit->distance >= t_max) return std::nullopt;
        return hit;
    }
    std::optional<BoundaryHit> plane_ahead(glm::dvec3 origin, glm::dvec3 direction,
                                           bool inside) const {
        if (!inside) return std::nullopt;
        if (direction.z > 0.0) {
            // A semi-infinite slab's far face is at infinity: a walk always collides
            // before it (sigma_t = 1).
            if (std::isinf(depth)) return BoundaryHit{depth, {0.0, 0.0, 1.0}, 1};
            return BoundaryHit{
                std::max(0.0, (depth - origin.z) / direction.z), {0.0, 0.0, 1.0}, 1};
        }
        if (direction.z < 0.0)
            return BoundaryHit{
                std::max(0.0, -origin.z / direction.z), {0.0, 0.0, -1.0}, 0};
        return std::nullopt;  // parallel to the faces: it never leaves (an infinite slab)
    }
};

struct Sums {
    double specular = 0, specular2 = 0, diffuse = 0, diffuse2 = 0, transmitted = 0,
           transmitted2 = 0, reflected = 0, reflected2 = 0;
    WalkCounters counters;
    void add(const Sums& o) {
        specular += o.specular, specular2 += o.specular2, diffuse += o.diffuse,
            diffuse2 += o.diffuse2, transmitted += o.transmitted,
            transmitted2 += o.transmitted2, reflected += o.reflected,
            reflected2 += o.reflected2;
        counters.add(o.counters);
    }
};

Tally tally(double sum, double sum2, double n) {
    const double mean = sum / n;
    const double variance = std::max(0.0, sum2 / n - mean * mean);
    return {mean, n > 1 ? std::sqrt(variance / (n - 1)) : 0.0};
}

void run_path(const SlabProblem& problem, std::uint64_t index, Sums& sums) {
    Random random(problem.seed, index);
    ChannelMedium medium;
    medium.sigma_s = problem.albedo;
    medium.sigma_a = 1.0 - problem.albedo;
    medium.g = problem.g;
    const SlabBoundary boundary{problem.optical_depth};
    double mu = problem.incidence_cosine;
    if (problem.diffuse_incidence) mu = std::sqrt(random.uniform());
    mu = std::max(mu, 1e-12);
    const double phi = 2.0 * kPi * random.uniform();
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const glm::dvec3 incident{sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu};
    double specular = 0, diffuse = 0, transmitted = 0;
    if (problem.eta == 1.0 && problem.shortcuts.skip_fresnel_at_eta_1) {
        walk(
            boundary, medium, problem.eta, {0, 0, 0}, incident, true, 1.0, random,
            problem.shortcuts, problem.limits, sums.counters,
            [](glm::dvec3, glm::dvec3, double) {},
            [&](const Escape& e) {
                (e.direction.z < 0 ? diffuse : transmitted) += e.weight;
            });
    } else {
        ++sums.counters.interface_events;
        const InterfaceEvent entry =
            cross_interface(incident, {0.0, 0.0, -1.0}, problem.eta, random.uniform());
        if (!entry.transmitted) {
            specular = 1.0;
        } else {
            walk(
                boundary, medium, problem.eta, {0, 0, 0}, entry.direction, true, 1.0,
                random, problem.shortcuts, problem.limits, sums.counters,
                [](glm::dvec3, glm::dvec3, double) {},
                [&](const Escape& e) {
                    (e.direction.z < 0 ? diffuse : transmitted) += e.weight;
                });
        }
    }
    const double reflected = specular + diffuse;
    sums.specular += specular, sums.specular2 += specular * specular;
    sums.diffuse += diffuse, sums.diffuse2 += diffuse * diffuse;
    sums.transmitted += transmitted, sums.transmitted2 += transmitted * transmitted;
    sums.reflected += reflected, sums.reflected2 += reflected * reflected;
}

}  // namespace

void check_slab_problem(const SlabProblem& p) {
    if (!(p.albedo >= 0.0 && p.albedo <= 1.0))
        throw std::invalid_argument("--albedo: must lie in [0, 1]");
    if (!(p.g > -1.0 && p.g < 1.0))
        throw std::invalid_argument("--g: must lie in (-1, 1)");
    if (!(p.optical_depth >= 0.0))
        throw std::invalid_argument("--optical-depth: must be >= 0 or inf");
    if (!(p.eta >= 1.0 / 4.0 && p.eta <= 4.0 && std::isfinite(p.eta)))
        throw std::invalid_argument("--eta: must lie in [0.25, 4]");
    if (!p.diffuse_incidence && !(p.incidence_cosine > 0.0 && p.incidence_cosine <= 1.0))
        throw std::invalid_argument(
            "--incidence: must be a cosine in (0, 1] or 'diffuse'");
    if (p.paths < 2) throw std::invalid_argument("--paths: must be at least 2");
}

SlabResult run_slab(const SlabProblem& problem) {
    check_slab_problem(problem);
    const auto start = std::chrono::steady_clock::now();
    constexpr std::uint64_t kBlock = 1024;
    const std::uint64_t blocks = (problem.paths + kBlock - 1) / kBlock;
    std::vector<Sums> block_sums(blocks);
    std::atomic<std::uint64_t> next{0};
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> workers;
    for (unsigned t = 0; t < threads; ++t)
        workers.emplace_back([&] {
            for (std::uint64_t b; (b = next.fetch_add(1)) < blocks;) {
                const std::uint64_t end = std::min(problem.paths, (b + 1) * kBlock);
                for (std::uint64_t i = b * kBlock; i < end; ++i)
                    run_path(problem, i, block_sums[b]);
            }
        });
    for (std::thread& worker : workers) worker.join();
    // Summed in block order, so the floating-point sums do not depend on the threads.
    Sums total;
    for (const Sums& s : block_sums) total.add(s);
    const double n = double(problem.paths);
    SlabResult result;
    result.specular_reflectance = tally(total.specular, total.specular2, n);
    result.diffuse_reflectance = tally(total.diffuse, total.diffuse2, n);
    result.total_transmittance = tally(total.transmitted, total.transmitted2, n);
    result.total_reflectance = tally(total.reflected, total.reflected2, n);
    result.counters = total.counters;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace lucent::path
