// The path technique's image: per pixel and channel, walks (walk.h) from the eye through
// the pixel centre into the mesh's medium, lit by the uniform environment and the key
// light's disc, with next-event estimation of the key light at each scattering where the
// interface is index-matched (eta = 1; through a smooth dielectric no shadow ray can
// reach a light), combined with the phase-sampled hits by the power heuristic.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "common/content_hash.h"
#include "common/cpu_time.h"
#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/path/path.h"
#include "renderer/techniques/path/walk.h"

namespace lucent::path {
namespace {

// The mesh as the medium's boundary: the nearest crossing through Embree, with the
// geometric normal (the mesh is closed and faces out, check_scene: so it points out of
// the medium). Crossings closer than the caster's layer epsilon are skipped, so a walk
// never meets the point it stands on again.
struct MeshBoundary {
    const RayCaster& caster;
    float epsilon;
    double spawn_offset() const { return epsilon; }
    std::optional<BoundaryHit> nearest(glm::dvec3 origin, glm::dvec3 direction,
                                       bool /*inside*/, double t_max) const {
        const float far = t_max < 1e30 ? float(t_max) : 1e30f;
        if (!(far > epsilon)) return std::nullopt;
        const std::optional<RayHit> hit =
            caster.first_hit(glm::vec3(origin), glm::vec3(direction), epsilon, far);
        if (!hit) return std::nullopt;
        return BoundaryHit{double(hit->distance), glm::dvec3(hit->geometric_normal),
                           hit->triangle};
    }
};

// The key light as seen from the object: a disc of angular radius `radius` (radians)
// around `direction`, of radiance Id / (pi sin^2 radius) so that its irradiance at
// normal incidence is Id whatever the radius (Id itself for radius 0: a direction).
struct KeyLight {
    glm::dvec3 direction{0.0, 0.0, 1.0};  // object space, towards the light
    double radius = 0.0;
    double cos_radius = 1.0;
    double solid_angle = 0.0;  // 2 pi (1 - cos radius)
    glm::dvec3 radiance{0.0};  // per channel; for radius 0: the irradiance Id
    bool on = false;
    bool in_disc(glm::dvec3 d) const {
        return radius > 0.0 && glm::dot(d, direction) >= cos_radius;
    }
};

KeyLight key_light(const Scene& scene, const Params& p, bool full) {
    KeyLight light;
    const glm::dmat3 rotation(glm::dmat4(scene.camera.view()));
    light.direction =
        glm::normalize(glm::transpose(rotation) * glm::dvec3(scene.light.direction));
    light.radius = p.light_radius * kPi / 180.0;
    const double half_sin = std::sin(0.5 * light.radius);
    light.solid_angle =
        4.0 * kPi * half_sin * half_sin;  // 2 pi (1 - cos r), no cancellation
    light.cos_radius = 1.0 - 2.0 * half_sin * half_sin;
    const double sin_radius = std::sin(light.radius);
    const glm::dvec3 id(scene.light.diffuse);
    light.radiance = light.radius > 0.0 ? id / (kPi * sin_radius * sin_radius) : id;
    light.on = full || id != glm::dvec3(0.0);
    return light;
}

// A direction uniform in the light's cone.
glm::dvec3 sample_cone(const KeyLight& light, double u1, double u2) {
    const double cos_theta = 1.0 - u1 * (1.0 - light.cos_radius);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    const double phi = 2.0 * kPi * u2;
    return glm::normalize(
        Frame(light.direction)
            .to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta}));
}

double power_heuristic(double a, double b) {
    const double a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

struct Tracer {
    const Scene& scene;
    Params p;
    bool full;
    double eta;
    ChannelMedium media[3];
    KeyLight light;
    glm::dvec3 environment;
    const RayCaster& caster;
    MeshBoundary boundary;
    WalkShortcuts shortcuts;
    WalkLimits limits;
    bool next_event;  // eta = 1: shadow rays reach the key light
    // eta != 1: shadow rays reach it through one flat facet (connect_through_facet)
    bool next_event_through_facet;

    // The path from `x` inside the medium through one facet of the boundary to the
    // outside direction `out`: the inside direction whose refraction at the facet it
    // meets is `out`. The facet is found by iteration (aim, see which facet the ray
    // meets, aim by that facet's normal, ...) and the connection holds once a ray aimed
    // by a facet's normal meets that facet; nothing after 4 tries. Deterministic in
    // (x, out), so the phase-sampled side can ask whether this would have found its path.
    struct FacetConnection {
        glm::dvec3 direction;  // from x, inside
        double distance = 0.0;
        glm::dvec3 outward;
        std::uint32_t facet = 0;
        double cos_inside = 1.0, cos_outside = 1.0;
    };
    std::optional<FacetConnection> connect_through_facet(glm::dvec3 x,
                                                         glm::dvec3 out) const {
        glm::dvec3 aim = out;
        std::optional<std::uint32_t> aimed_by;
        double cos_inside = 1.0, cos_outside = 1.0;
        for (int attempt = 0; attempt < 5; ++attempt) {
            const std::optional<BoundaryHit> hit =
                boundary.nearest(x, aim, true, INFINITY);
            if (!hit) return std::nullopt;
            if (aimed_by && *aimed_by == hit->facet)
                return FacetConnection{aim,        hit->distance, hit->outward,
                                       hit->facet, cos_inside,    cos_outside};
            const glm::dvec3 n = hit->outward;
            cos_outside = glm::dot(out, n);
            if (!(cos_outside > 1e-9) || attempt == 4) return std::nullopt;
            // Light arriving along -out refracts into the medium along -aim (Snell).
            const double sin2_inside = (1.0 - cos_outside * cos_outside) / (eta * eta);
            cos_inside = std::sqrt(std::max(0.0, 1.0 - sin2_inside));
            aim = glm::normalize(out / eta + (cos_inside - cos_outside / eta) * n);
            aimed_by = hit->facet;
        }
        return std::nullopt;
    }
    // The density over inside directions with which next-event estimation through a
    // facet chooses a connection: uniform over the disc's solid angle outside, times
    // d omega_out / d omega_in = eta^2 cos_in / cos_out.
    double facet_connection_pdf(const FacetConnection& c) const {
        return eta * eta * c.cos_inside /
               (std::max(c.cos_outside, 1e-12) * light.solid_angle);
    }

    // Transmittance from `origin` (inside the medium) along `direction` to infinity,
    // through every crossing of the index-matched boundary.
    double shadow_transmittance(const ChannelMedium& medium, glm::dvec3 origin,
                                glm::dvec3 direction, Random& random,
                                WalkCounters& counters) const {
        double t = 1.0;
        bool inside = true;
        for (int crossings = 0; crossings < 1024 && t > 0.0; ++crossings) {
            const std::optional<BoundaryHit> hit =
                boundary.nearest(origin, direction, inside, INFINITY);
            if (!hit) return t;
            if (inside)
                t *= transmittance(medium, origin, direction, hit->distance, random,
                                   shortcuts, counters);
            origin += hit->distance * direction;
            inside = !inside;
            origin += (inside ? -hit->outward : hit->outward) * boundary.spawn_offset();
        }
        return 0.0;
    }

    // One path's radiance estimate in `channel` for the ray from the eye along
    // `direction`.
    double radiance(glm::dvec3 eye, glm::dvec3 direction, int channel, Random& random,
                    WalkCounters& counters) const {
        const ChannelMedium& medium = media[channel];
        double sum = 0.0;
        const auto on_scatter = [&](glm::dvec3 position, glm::dvec3 incoming,
                                    double weight) {
            if (!(next_event || next_event_through_facet) || !light.on) return;
            if (light.radius == 0.0) {
                const double phase =
                    henyey_greenstein(medium.g, glm::dot(incoming, light.direction));
                sum += weight * phase * light.radiance[channel] *
                       shadow_transmittance(medium, position, light.direction, random,
                                            counters);
                return;
            }
            const glm::dvec3 to_light =
                sample_cone(light, random.uniform(), random.uniform());
            if (next_event_through_facet) {
                const std::optional<FacetConnection> c =
                    connect_through_facet(position, to_light);
                if (!c) return;
                const glm::dvec3 exit = position + c->distance * c->direction;
                if (boundary.nearest(exit + c->outward * boundary.spawn_offset(),
                                     to_light, false, INFINITY))
                    return;  // the object is in the way outside
                const double pdf = facet_connection_pdf(*c);
                const double phase =
                    henyey_greenstein(medium.g, glm::dot(incoming, c->direction));
                const double transmitted =
                    1.0 - fresnel_dielectric(c->cos_inside, 1.0 / eta);
                sum += weight * phase * transmitted * light.radiance[channel] / pdf *
                       power_heuristic(pdf, phase) *
                       transmittance(medium, position, c->direction, c->distance, random,
                                     shortcuts, counters);
                return;
            }
            const double light_pdf = 1.0 / light.solid_angle;
            const double phase =
                henyey_greenstein(medium.g, glm::dot(incoming, to_light));
            sum += weight * phase * light.radiance[channel] / light_pdf *
                   power_heuristic(light_pdf, phase) *
                   shadow_transmittance(medium, position, to_light, random, counters);
        };
        const auto on_escape = [&](const Escape& e) {
            if (e.direct) {
                sum += scene.background[channel];
                return;
            }
            double seen = environment[channel];
            if (light.on && light.in_disc(e.direction)) {
                // A phase sample that next-event estimation also covers (eta = 1, the
                // last event a scattering) shares the light by the power heuristic; a
                // hit no shadow ray could have made (no scattering since the eye, or a
                // refracting interface on the way) counts whole.
                double mis = next_event && e.phase_pdf > 0.0
                                 ? power_heuristic(e.phase_pdf, 1.0 / light.solid_angle)
                                 : 1.0;
                // Through one facet: shared with the connection that would have found
                // this very path (the same facet from the same scattering).
                if (next_event_through_facet && e.one_refraction_after_scattering)
                    if (const std::optional<FacetConnection> c =
                            connect_through_facet(e.scattering_position, e.direction);
                        c && c->facet == e.exit_facet)
                        mis = power_heuristic(e.scattering_phase_pdf,
                                              facet_connection_pdf(*c));
                seen += light.radiance[channel] * mis;
            }
            sum += e.weight * seen;
        };
        walk(boundary, medium, eta, eye, direction, false, 1.0, random, shortcuts, limits,
             counters, on_scatter, on_escape);
        return sum;
    }
};

std::uint64_t sample_seed(int seed, int sample) {
    return common::ContentHash()
        .word(std::uint32_t(seed))
        .word(std::uint32_t(sample))
        .result();
}

}  // namespace

EstimatedImage render_path(const Scene& scene, const TraceOptions& options,
                           TraceStatistics* statistics) {
    const auto start = std::chrono::steady_clock::now();
    const Params p = params(scene);
    const RayCaster caster(*scene.mesh);
    Tracer tracer{scene,
                  p,
                  options.full,
                  medium_eta(p),
                  {channel_medium(scene, p, 0), channel_medium(scene, p, 1),
                   channel_medium(scene, p, 2)},
                  key_light(scene, p, options.full),
                  glm::dvec3(scene.light.ambient),
                  caster,
                  MeshBoundary{caster, caster.layer_epsilon()},
                  options.full ? WalkShortcuts::none() : WalkShortcuts{},
                  WalkLimits{1'000'000, 0.1},
                  false,
                  false};
    tracer.next_event = tracer.eta == 1.0 && options.light_sampling;
    tracer.next_event_through_facet =
        tracer.eta != 1.0 && tracer.light.radius > 0.0 && options.light_sampling;
    // A walk after a path that met a point of the scene with a light only in other
    // channels contributes nothing in this one: with no light in a channel, skip its
    // walks.
    bool channel_lit[3];
    for (int c = 0; c < 3; ++c)
        channel_lit[c] = options.full || tracer.environment[c] != 0.0 ||
                         (tracer.light.on && tracer.light.radiance[c] != 0.0);

    const PixelRays rays(scene.camera, scene.width, scene.height);
    const int width = scene.width, height = scene.height;
    const std::size_t pixels = std::size_t(width) * height;
    std::vector<double> sum(pixels * 3, 0.0), sum2(pixels * 3, 0.0);
    std::vector<float> coverage(pixels, 0.0f);
    for (int row = 0; row < height; ++row)
        for (int x = 0; x < width; ++x)
            if (caster.first_hit(glm::vec3(rays.eye()),
                                 glm::vec3(rays.direction(x, row))))
                coverage[std::size_t(row) * width + x] = 1.0f;

    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<WalkCounters> thread_counters(threads);
    std::vector<double> thread_cpu(threads, 0.0);
    int samples_done = 0;
    for (int sample = 0; sample < p.paths; ++sample) {
        const std::uint64_t seed = sample_seed(p.seed, sample);
        std::atomic<int> next_row{0};
        std::vector<std::thread> workers;
        for (unsigned t = 0; t < threads; ++t)
            workers.emplace_back([&, t] {
                const double cpu_start = common::thread_cpu_seconds();
                for (int row; (row = next_row.fetch_add(1)) < height;)
                    for (int x = 0; x < width; ++x) {
                        const std::size_t pixel = std::size_t(row) * width + x;
                        const glm::dvec3 direction = rays.direction(x, row);
                        for (int c = 0; c < 3; ++c) {
                            double value = 0.0;
                            if (channel_lit[c] || coverage[pixel] == 0.0f) {
                                Random random(seed, pixel * 3 + c);
                                value = tracer.radiance(rays.eye(), direction, c, random,
                                                        thread_counters[t]);
                            }
                            sum[pixel * 3 + c] += value;
                            sum2[pixel * 3 + c] += value * value;
                        }
                    }
                thread_cpu[t] += common::thread_cpu_seconds() - cpu_start;
            });
        for (std::thread& worker : workers) worker.join();
        samples_done = sample + 1;
        if (options.produce.progress)
            options.produce.progress(std::size_t(samples_done), std::size_t(p.paths));
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                .count();
        if (p.time_budget > 0.0 && elapsed >= p.time_budget) break;
    }

    EstimatedImage estimate;
    estimate.mean = Image(width, height);
    estimate.standard_error = Image(width, height);
    const double n = samples_done;
    double largest_error = 0.0, error_sum = 0.0;
    std::size_t covered = 0;
    for (int row = 0; row < height; ++row)
        for (int x = 0; x < width; ++x) {
            const std::size_t pixel = std::size_t(row) * width + x;
            glm::vec4 mean(0.0f, 0.0f, 0.0f, coverage[pixel]), error(0.0f);
            for (int c = 0; c < 3; ++c) {
                const double m = sum[pixel * 3 + c] / n;
                const double variance =
                    n > 1 ? std::max(0.0, (sum2[pixel * 3 + c] - n * m * m) / (n - 1))
                          : 0.0;
                const double se = n > 1 ? std::sqrt(variance / n) : 0.0;
                mean[c] = float(m);
                error[c] = float(se);
                if (coverage[pixel] > 0.0f) {
                    largest_error = std::max(largest_error, se);
                    error_sum += se;
                }
            }
            covered += coverage[pixel] > 0.0f;
            estimate.mean.set(x, row, mean);
            estimate.standard_error.set(x, row, error);
        }
    WalkCounters counters;
    for (const WalkCounters& c : thread_counters) counters.add(c);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double cpu_seconds = 0.0;
    for (const double c : thread_cpu) cpu_seconds += c;
    if (statistics) *statistics = {counters, cpu_seconds, seconds, samples_done};
    char line[512];
    std::snprintf(
        line, sizeof line,
        "path: %d of %d samples per pixel and channel in %.2f s; standard error on "
        "object pixels mean %.3g, max %.3g; %llu scattering events (%.3g per "
        "CPU-second); %llu walks stopped at the event cap, %llu leaks",
        samples_done, p.paths, seconds,
        covered ? error_sum / (3.0 * double(covered)) : 0.0, largest_error,
        static_cast<unsigned long long>(counters.scattering_events),
        seconds > 0 ? double(counters.scattering_events) / (seconds * threads) : 0.0,
        static_cast<unsigned long long>(counters.unfinished),
        static_cast<unsigned long long>(counters.leaks));
    estimate.summary = line;
    return estimate;
}

}  // namespace lucent::path
