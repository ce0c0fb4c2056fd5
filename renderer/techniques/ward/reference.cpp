// CPU reference of the ward and contrast_reversed techniques, independent of the GL
// passes: Embree casts one ray through each pixel centre; the first hit inside the
// near/far planes gives the interpolated normal, AO and eye-space position, and shade()
// evaluates Eq. 14 / Eq. 15 with ward_brdf.h in double precision.
#include <algorithm>
#include <cmath>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/ward/ward.h"
#include "renderer/techniques/ward/ward_brdf.h"

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
    const PixelRays rays(scene.camera, scene.width, scene.height);
    const RayCaster caster(mesh);
    return shade_front_hits(
        rays, caster, scene.background, [&](glm::dvec3 direction, const RayHit& front) {
            // Interpolated normal and AO (barycentric, as the rasteriser), eye space.
            const SurfaceSample surface = interpolate_at(mesh, front, vertex_ao);
            const glm::dvec3 normal = rays.normal_matrix() * surface.normal;
            const double n2 = glm::dot(normal, normal);
            const glm::dvec3 n =
                n2 > 1e-30 ? normal / std::sqrt(n2) : glm::dvec3(0.0, 0.0, 1.0);
            const double ao = surface.ao;
            // View vector: from the hit point back to the eye, in eye space.
            const glm::dvec3 to_eye = glm::dmat3(rays.view()) * -direction;
            return shade(p, scene.light, variant, n, to_eye, ao);
        });
}

}  // namespace lucent::ward
