// CPU reference of the htsm technique, independent of the GL passes (no rasteriser, no
// mips, no tables): the light image is ray cast with Embree at F x W_L rays per side and
// kept as summed-area tables (double), so each pattern sample averages exactly its
// square footprint h_L 2^lambda (outside the light plane counts as 0); camera rays by
// Embree; a fine midpoint march through the same voxels (CPU trilinear, the GL texel
// convention); exact Henyey-Greenstein; Embree shadow rays for the surface terms.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "renderer/cpu/blinn_phong.h"
#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/htsm/htsm.h"

namespace lucent::htsm {
namespace {

// Summed-area tables of coverage A, A t (3) and E (3) over the fine light image.
class LightImage {
public:
    static constexpr int kChannels = 7;

    LightImage(const Scene& scene, const Params& p, const Geometry& g,
               const RayCaster& caster, int oversample)
        : size_(std::clamp(oversample, 1, 16) * p.light_map_size) {
        size_ = std::min(size_, 2048);
        const int n = size_ + 1;
        for (auto& table : sat_) table.assign(std::size_t(n) * n, 0.0);
        std::vector<std::array<double, kChannels>> texels(std::size_t(size_) * size_);
        const LightView& l = g.light;
        const double plane = 2.0 * l.radius;
        const glm::dvec3 id = scene.light.diffuse;
        for_each_row_parallel(size_, [&](int y) {
            for (int x = 0; x < size_; ++x) {
                auto& texel = texels[std::size_t(y) * size_ + x];
                texel.fill(0.0);
                const glm::dvec3 origin =
                    glm::dvec3(l.centre) +
                    ((x + 0.5) / size_ - 0.5) * plane * glm::dvec3(l.right) +
                    ((y + 0.5) / size_ - 0.5) * plane * glm::dvec3(l.up) +
                    plane * g.to_light;
                const auto hit = caster.first_hit(
                    glm::vec3(origin), glm::vec3(-g.to_light), 0.0f, float(2.0 * plane));
                if (!hit) continue;
                const glm::dvec3 y_point = origin - double(hit->distance) * g.to_light;
                const glm::dvec3 t = (y_point - g.box_min) / g.box_extent;
                const glm::dvec3 normal = interpolate_at(*scene.mesh, *hit, {}).normal;
                const double length = glm::length(normal);
                const double c =
                    length > 0.0 ? glm::dot(normal / length, g.to_light) : 0.0;
                const glm::dvec3 e =
                    c > 0.0 ? id * (c * (1.0 - schlick(p.ior, c))) : glm::dvec3(0.0);
                texel = {1.0, t.x, t.y, t.z, e.x, e.y, e.z};
            }
        });
        // Prefix sums in double: sat(X, Y) = sum of texels with x < X, y < Y.
        for (int c = 0; c < kChannels; ++c)
            for (int y = 0; y < size_; ++y) {
                double row = 0.0;
                for (int x = 0; x < size_; ++x) {
                    row += texels[std::size_t(y) * size_ + x][c];
                    at(c, x + 1, y + 1) = at(c, x + 1, y) + row;
                }
            }
    }

    int size() const { return size_; }

    // Means over the box [x0, x1] x [y0, y1] in fine texels (real-valued, may reach
    // outside the image, where everything is 0): the SAT interpolated bilinearly is the
    // exact integral of the piecewise-constant image.
    std::array<double, kChannels> box_mean(double x0, double y0, double x1,
                                           double y1) const {
        std::array<double, kChannels> mean{};
        const double area = (x1 - x0) * (y1 - y0);
        if (!(area > 0.0)) return mean;
        for (int c = 0; c < kChannels; ++c)
            mean[c] = (integral(c, x1, y1) - integral(c, x0, y1) - integral(c, x1, y0) +
                       integral(c, x0, y0)) /
                      area;
        return mean;
    }

private:
    double& at(int c, int x, int y) { return sat_[c][std::size_t(y) * (size_ + 1) + x]; }
    double get(int c, int x, int y) const {
        return sat_[c][std::size_t(y) * (size_ + 1) + x];
    }
    double integral(int c, double x, double y) const {
        x = std::clamp(x, 0.0, double(size_));
        y = std::clamp(y, 0.0, double(size_));
        const int i = std::min(int(x), size_ - 1), j = std::min(int(y), size_ - 1);
        const double fx = x - i, fy = y - j;
        return (1 - fx) * (1 - fy) * get(c, i, j) + fx * (1 - fy) * get(c, i + 1, j) +
               (1 - fx) * fy * get(c, i, j + 1) + fx * fy * get(c, i + 1, j + 1);
    }

    int size_;
    std::array<std::vector<double>, kChannels> sat_;
};

}  // namespace

Image render_reference(const Scene& scene, const ReferenceQuality& quality) {
    const Params p = params(scene);
    const Geometry g = geometry(scene, p);
    const Mesh& mesh = *scene.mesh;
    const RayCaster caster(mesh);
    const bool transport = has_transport(p, scene);
    const bool surface = has_surface(p, scene);
    const std::vector<PatternSample> samples = pattern(p, g);
    const LightView& l = g.light;
    const double plane = 2.0 * l.radius;
    const double eps_d = 2.0 * g.texel;
    const int steps = std::max(quality.steps, 1);
    const double kappa = p.density_scale;
    const DensityVolume* density = scene.density.get();
    std::optional<LightImage> light;
    if (transport) light.emplace(scene, p, g, caster, quality.oversample);
    const double fine_per_plane = light ? light->size() / plane : 0.0;

    const glm::dvec3 l_eye = scene.light.direction;
    const PixelRays rays(scene.camera, scene.width, scene.height);
    return shade_front_hits(
        rays, caster, scene.background, [&](glm::dvec3 direction, const RayHit& front) {
            const glm::dvec3 point = rays.eye() + double(front.distance) * direction;
            const glm::dvec3 normal_raw = interpolate_at(mesh, front, {}).normal;
            const double n_length = glm::length(normal_raw);
            const glm::dvec3 n =
                n_length > 0.0 ? normal_raw / n_length : glm::dvec3(0, 0, 1);
            glm::dvec3 colour(0.0);
            if (transport) {
                // Table 4.1 over the pattern, each footprint averaged exactly.
                const glm::dvec3 rel = point - glm::dvec3(l.centre);
                const glm::dvec2 uv = glm::dvec2(glm::dot(rel, glm::dvec3(l.right)),
                                                 glm::dot(rel, glm::dvec3(l.up))) /
                                          plane +
                                      0.5;
                const glm::dvec3 start = (point - g.box_min) / g.box_extent;
                glm::dvec3 sum(0.0);
                for (const PatternSample& s : samples) {
                    const glm::dvec2 uv_i = uv + s.offset / plane;
                    if (uv_i.x < 0 || uv_i.y < 0 || uv_i.x > 1 || uv_i.y > 1) continue;
                    const double half_box =
                        0.5 * g.texel * std::exp2(s.lod) * fine_per_plane;
                    const glm::dvec2 c = uv_i * double(light->size());
                    const auto m = light->box_mean(c.x - half_box, c.y - half_box,
                                                   c.x + half_box, c.y + half_box);
                    if (m[0] < 1e-4) continue;
                    const glm::dvec3 end = glm::dvec3(m[1], m[2], m[3]) / m[0];
                    const glm::dvec3 e(m[4], m[5], m[6]);
                    const glm::dvec3 d = (end - start) * g.box_extent;
                    const double len = glm::length(d);
                    const double ray = len / g.phi;
                    double alpha = 0.0;
                    if (density && kappa > 0.0) {
                        double accumulated = 0.0;
                        for (int k = 0; k < steps; ++k)
                            accumulated += density->sample(start + (k + 0.5) / steps *
                                                                       (end - start));
                        alpha = kappa * ray * accumulated / steps;
                    }
                    const double weight =
                        transport_weight(ray + alpha, p.transport_distance);
                    const glm::dvec3 dir =
                        glm::normalize(d + std::max(0.0, eps_d - len) * g.to_light);
                    sum += e * (weight * phase(p.phase_g, glm::dot(dir, -n)));
                }
                colour += p.transport_colour * sum / double(samples.size());
            }
            if (surface) {
                // Diffuse and specular where N.L > 0 and nothing occludes the light.
                const glm::dvec3 n_eye = glm::normalize(rays.normal_matrix() * n);
                const double n_dot_l = glm::dot(n_eye, l_eye);
                if (n_dot_l > 0.0) {
                    glm::dvec3 geometric(front.geometric_normal);
                    if (glm::dot(geometric, g.to_light) < 0.0) geometric = -geometric;
                    const glm::dvec3 origin = point + 1e-4 * g.phi * geometric;
                    if (!caster.occluded(glm::vec3(origin), glm::vec3(g.to_light), 0.0f,
                                         1e30f)) {
                        const double lobe = blinn_phong_lobe(n_eye, l_eye, p.shininess);
                        colour += p.diffuse * p.albedo * glm::dvec3(scene.light.diffuse) *
                                      n_dot_l +
                                  p.specular * glm::dvec3(scene.light.specular) * lobe;
                    }
                }
            }
            return colour;
        });
}

Image render_reference_with_error(const Scene& scene, const ReferenceQuality& quality,
                                  ReferenceError& error) {
    const Image coarse = render_reference(scene, quality.halved());
    Image fine = render_reference(scene, quality);
    error = reference_error(coarse, fine);
    return fine;
}

}  // namespace lucent::htsm
