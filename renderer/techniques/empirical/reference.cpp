// CPU reference of the empirical technique, independent of the GL passes: Embree casts
// one ray through each pixel centre; its first and second hits are the exact two depth
// layers (no depth buffer, no peeling epsilon beyond the thesis's). Then the same
// smoothing (Eq. C.1) and lighting (Eq. 3.6) run in double precision.
#include <algorithm>
#include <cmath>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/cpu/blinn_phong.h"
#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/empirical/empirical.h"

namespace lucent::empirical {
namespace {

constexpr double kNoLayer = 1.0;  // window depth of "no surface" (cleared depth)

struct Layers {
    std::vector<double> front;   // window depth, kNoLayer where the ray misses
    std::vector<double> second;  // window depth of the second layer, or kNoLayer
    std::vector<glm::dvec3>
        normal;              // interpolated vertex normal at the front hit (eye space)
    std::vector<double> ao;  // interpolated AO at the front hit
};

// x^e with x^0 = 1 and non-positive bases giving 0 (as the shader's power()).
double power(double x, double e) {
    if (e == 0.0) return 1.0;
    return x <= 0.0 ? 0.0 : std::pow(x, e);
}

Layers cast_layers(const Scene& scene, const std::vector<float>& vertex_ao) {
    const Mesh& mesh = *scene.mesh;
    const int w = scene.width, h = scene.height;
    const double n = scene.camera.near_plane, f = scene.camera.far_plane;
    const PixelRays rays(scene.camera, w, h);
    const double epsilon = 1e-6;  // the thesis's; the reference has exact depths
    const RayCaster caster(mesh);

    // Eq. 3.3 inverted: eye-space distance -> window depth.
    const auto window_depth = [&](double z) {
        return 0.5 * ((f + n) / (f - n) - 2.0 * f * n / ((f - n) * z)) + 0.5;
    };

    Layers layers;
    const std::size_t count = static_cast<std::size_t>(w) * h;
    layers.front.assign(count, kNoLayer);
    layers.second.assign(count, kNoLayer);
    layers.normal.assign(count, glm::dvec3(0.0));
    layers.ao.assign(count, 0.0);
    for_each_row_parallel(h, [&](int row) {
        for (int x = 0; x < w; ++x) {
            const glm::dvec3 direction = rays.direction(x, row);
            const auto hits = caster.hits(glm::vec3(rays.eye()), glm::vec3(direction), 8);
            const std::size_t i = static_cast<std::size_t>(row) * w + x;
            bool have_front = false;
            for (const RayHit& hit : hits) {
                const double z = rays.eye_depth(hit.distance, direction);
                if (z < n || z > f) continue;  // clipped by the near/far planes
                const double d = window_depth(z);
                if (d >= 1.0) continue;  // fails the depth test against the clear
                if (!have_front) {
                    have_front = true;
                    layers.front[i] = d;
                    const SurfaceSample surface = interpolate_at(mesh, hit, vertex_ao);
                    layers.normal[i] = rays.normal_matrix() * surface.normal;
                    layers.ao[i] = surface.ao;
                } else if (d > layers.front[i] + epsilon) {
                    layers.second[i] = d;  // App. B: nearest depth behind front + epsilon
                    break;
                }
            }
        }
    });
    return layers;
}

// App. C.2.2, Eq. C.1, with clamp-to-edge addressing (as the shader).
std::vector<double> smooth(const std::vector<double>& depth, int w, int h, int size) {
    if (size <= 1) return depth;
    const double* kernel = size == 5 ? kKernel5.data() : kKernel3.data();
    const int radius = size / 2;
    std::vector<double> out(depth.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double d0 = depth[static_cast<std::size_t>(y) * w + x];
            if (d0 >= kNoLayer) {
                out[static_cast<std::size_t>(y) * w + x] = kNoLayer;
                continue;
            }
            double sum = 0.0, total = 0.0;
            for (int j = -radius; j <= radius; ++j)
                for (int i = -radius; i <= radius; ++i) {
                    const int sx = std::clamp(x + i, 0, w - 1),
                              sy = std::clamp(y + j, 0, h - 1);
                    const double d = depth[static_cast<std::size_t>(sy) * w + sx];
                    if (d >= kNoLayer) continue;
                    const double weight =
                        kernel[(j + radius) * size + (i + radius)] *
                        (1.0 -
                         std::clamp(std::abs(d - d0) / kSmoothingFalloff, 0.0, 1.0));
                    sum += weight * d;
                    total += weight;
                }
            out[static_cast<std::size_t>(y) * w + x] = sum / total;
        }
    return out;
}

}  // namespace

Image render_reference(const Scene& scene) {
    const Params p = params(scene);
    const Light& light = scene.light;
    const bool ambient_term = p.ambient != 0.0 && light.ambient != glm::vec3(0.0f);
    std::vector<float> vertex_ao;
    if (ambient_term) {
        AoBakeOptions options;
        options.rays = p.ao_rays;
        vertex_ao = load_or_bake_ambient_occlusion(*scene.mesh, options);
    }
    const int w = scene.width, h = scene.height;
    const Layers layers = cast_layers(scene, vertex_ao);
    // Image rows are top first here, GL's bottom first; the kernel is symmetric, so
    // smoothing in either order gives the same result.
    const std::vector<double> back = smooth(layers.second, w, h, p.blur_kernel);

    const double n = scene.camera.near_plane, f = scene.camera.far_plane;
    const double diameter = scene.bounds.diameter();
    const auto eye_depth = [&](double window_depth) {  // Eq. 3.3
        const double ndc = 2.0 * window_depth - 1.0;
        return 2.0 * n * f / (f + n - ndc * (f - n));
    };
    const glm::dvec3 kd = p.albedo, ia = light.ambient, id = light.diffuse,
                     is = light.specular;
    const glm::dvec3 l = light.direction;

    Image image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            if (layers.front[i] >= kNoLayer) {
                image.set(x, y, glm::vec4(scene.background, 0.0f));
                continue;
            }
            const double length2 = glm::dot(layers.normal[i], layers.normal[i]);
            const glm::dvec3 normal = length2 > 1e-30
                                          ? layers.normal[i] / std::sqrt(length2)
                                          : glm::dvec3(0.0, 0.0, 1.0);
            glm::dvec3 colour(0.0);
            // Ambient term (Eq. 3.7)
            if (ambient_term) colour += layers.ao[i] * p.ambient * kd * ia;
            // Diffuse and specular terms (Eqs. 3.8-3.9), where N.L > 0
            const double n_dot_l = glm::dot(normal, l);
            if (n_dot_l > 0.0) {
                colour += p.diffuse_contribution * kd * id * n_dot_l;
                colour += p.specular_contribution * p.specular * is *
                          blinn_phong_lobe(normal, l, p.shininess);
            }
            // Thickness term (Eq. 3.10); no second layer counts as the full diameter.
            if (p.backlight != 0.0) {
                double t = 1.0;
                if (back[i] < kNoLayer && diameter > 0.0)
                    t = std::clamp(
                        (eye_depth(back[i]) - eye_depth(layers.front[i])) / diameter, 0.0,
                        1.0);
                colour += p.backlight * power(1.0 - t, p.thickness_exponent) *
                          (kd + glm::dvec3(p.diffuse_weight));
            }
            image.set(x, y, glm::vec4(glm::vec3(colour), 1.0f));
        }
    return image;
}

}  // namespace lucent::empirical
