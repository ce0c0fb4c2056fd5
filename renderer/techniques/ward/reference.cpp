// CPU reference of the ward and contrast_reversed techniques, independent of the GL
// passes: Embree casts one ray through each pixel centre; the first hit inside the
// near/far planes gives the interpolated normal, AO and eye-space position, and shade()
// evaluates Eq. 14 / Eq. 15 with ward_brdf.h in double precision.
#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_inverse.hpp>
#include <thread>

#include "core/ambient_occlusion.h"
#include "cpu/ray_caster.h"
#include "techniques/ward/ward.h"
#include "techniques/ward/ward_brdf.h"

namespace lucent::ward {

glm::dvec3 shade(const Params& p, const Light& light, Variant variant, glm::dvec3 n,
                 glm::dvec3 v, double ao) {
    const glm::dvec3 kd = p.albedo, id = light.diffuse, l = light.direction;
    const double lit = std::max(glm::dot(n, l), 0.0);
    glm::dvec3 colour(0.0);
    // Ambient: ka * Ia * Kd * ao
    if (has_ambient_term(p, light))
        colour += p.ambient * glm::dvec3(light.ambient) * kd * ao;
    // Diffuse (Eq. 14), or reversed diffuse (Eq. 15 with Eq. 12 on luminance, Li = Id):
    // the backlit luminance 1 - Y(Kd) N.L, in the albedo's hue
    if (variant == Variant::ward) {
        colour += p.diffuse * kd * id * lit;
    } else {
        const double y = 0.2126 * kd.r + 0.7152 * kd.g + 0.0722 * kd.b;
        const glm::dvec3 chroma = y > 1e-6 ? kd / y : glm::dvec3(1.0);
        colour += p.diffuse * id * chroma * (1.0 - y * lit);
    }
    // Specular: pi * f_s * Is * max(N.L, 0), Ward's lobe (Eq. 13)
    if (has_specular_term(p, light))
        colour +=
            double(kPi) *
            double(ward_specular(glm::vec3(n), glm::vec3(l), glm::vec3(v),
                                 float(p.specular_reflectance), float(p.roughness))) *
            glm::dvec3(light.specular) * lit;
    return colour;
}

Image render_reference(const Scene& scene, Variant variant) {
    const Params p = params(scene, variant);
    const Mesh& mesh = *scene.mesh;
    std::vector<float> vertex_ao;
    if (has_ambient_term(p, scene.light)) {
        AoBakeOptions options;
        options.rays = p.ao_rays;
        vertex_ao = load_or_bake_ambient_occlusion(mesh, options);
    }
    const int w = scene.width, h = scene.height;
    const double near = scene.camera.near_plane, far = scene.camera.far_plane;
    const glm::dmat4 view = scene.camera.view();
    const glm::dmat4 inverse_view_projection =
        glm::inverse(glm::dmat4(scene.camera.projection()) * view);
    const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(view));
    const glm::dvec3 eye = scene.camera.eye;
    const glm::dvec3 forward = glm::normalize(glm::dvec3(scene.camera.target) - eye);
    const RayCaster caster(mesh);

    Image image(w, h);
    auto render_row = [&](int row) {
        const int gl_y = h - 1 - row;  // image rows are top first, GL's bottom first
        for (int x = 0; x < w; ++x) {
            // Ray through the pixel centre, from the eye (un-projected far point).
            const glm::dvec2 ndc((x + 0.5) / w * 2.0 - 1.0, (gl_y + 0.5) / h * 2.0 - 1.0);
            const glm::dvec4 far_point =
                inverse_view_projection * glm::dvec4(ndc, 1.0, 1.0);
            const glm::dvec3 direction =
                glm::normalize(glm::dvec3(far_point) / far_point.w - eye);
            const double cos_forward = glm::dot(direction, forward);
            // First hit the depth test keeps: between the near and far planes.
            std::optional<RayHit> front;
            for (const RayHit& hit :
                 caster.hits(glm::vec3(eye), glm::vec3(direction), 4)) {
                const double z = hit.distance * cos_forward;
                if (z >= near && z < far) {
                    front = hit;
                    break;
                }
            }
            if (!front) {
                image.set(x, row, glm::vec4(scene.background, 0.0f));
                continue;
            }
            // Interpolated normal and AO (barycentric, as the rasteriser), eye space.
            const glm::uvec3 tri = mesh.triangles[front->triangle];
            const double u = front->barycentric.x, v = front->barycentric.y,
                         t = 1.0 - u - v;
            const glm::dvec3 normal =
                normal_matrix * (t * glm::dvec3(mesh.normals[tri.x]) +
                                 u * glm::dvec3(mesh.normals[tri.y]) +
                                 v * glm::dvec3(mesh.normals[tri.z]));
            const double n2 = glm::dot(normal, normal);
            const glm::dvec3 n =
                n2 > 1e-30 ? normal / std::sqrt(n2) : glm::dvec3(0.0, 0.0, 1.0);
            const double ao =
                vertex_ao.empty()
                    ? 0.0
                    : t * vertex_ao[tri.x] + u * vertex_ao[tri.y] + v * vertex_ao[tri.z];
            // View vector: from the hit point back to the eye, in eye space.
            const glm::dvec3 to_eye = glm::dmat3(view) * -direction;
            image.set(x, row,
                      glm::vec4(glm::vec3(shade(p, scene.light, variant, n, to_eye, ao)),
                                1.0f));
        }
    };
    const int threads = int(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int k = 0; k < threads; ++k)
        pool.emplace_back([&, k] {
            for (int y = k; y < h; y += threads) render_row(y);
        });
    for (auto& thread : pool) thread.join();
    return image;
}

}  // namespace lucent::ward
