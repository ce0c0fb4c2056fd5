// CPU reference of the dipole technique, independent of the GL passes (no atlas, no
// samples, no light view): Embree casts one primary ray per pixel centre, and
// ScatteringIntegrator evaluates Eq. 3 over the subdivided surface with Embree shadow
// rays for visibility. Then L = Ft(eta, N.V) Id B / pi (Eq. 2), + ambient, the optional
// tone map, + Blinn-Phong specular, in double precision.
#include <cmath>

#include "renderer/core/ambient_occlusion.h"
#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/dipole/dipole.h"

namespace lucent::dipole {

Image render_reference(const Scene& scene, const IntegratorQuality& quality,
                       ReferenceStats* stats) {
    const Params p = params(scene);
    const Material material = material_of(p);
    const Mesh& mesh = *scene.mesh;
    const double scale = model_scale(mesh, p.model_size);
    const RayCaster caster(mesh);
    const bool subsurface = has_subsurface_term(p, scene);
    const ScatteringIntegrator integrator(mesh, scale, light_in_object_space(scene),
                                          subsurface ? material : Material{}, quality,
                                          &caster);
    if (stats) {
        stats->cells = integrator.cell_count();
        stats->cell_size_mm = integrator.cell_size();
        stats->flux = integrator.flux();
    }
    std::vector<float> vertex_ao;
    const bool ambient = has_ambient_term(p, scene);
    if (ambient) {
        AoBakeOptions options;
        options.rays = p.ao_rays;
        vertex_ao = load_or_bake_ambient_occlusion(mesh, options);
    }
    const bool tone_map = p.tone_map == "reinhard";
    const double average =
        tone_map ? tone_map_average(p, scene, integrator.flux(), integrator.total_area())
                 : 0.0;
    const glm::dvec3 id = scene.light.diffuse;
    const PixelRays rays(scene.camera, scene.width, scene.height);
    return shade_front_hits(
        rays, caster, scene.background, [&](glm::dvec3 direction, const RayHit& front) {
            const SurfaceSample surface = interpolate_at(mesh, front, vertex_ao);
            const double n2 = glm::dot(surface.normal, surface.normal);
            const glm::dvec3 n_object =
                n2 > 1e-30 ? surface.normal / std::sqrt(n2) : glm::dvec3(0.0, 0.0, 1.0);
            const double n_dot_v = std::max(glm::dot(n_object, -direction), 0.0);
            glm::dvec3 colour(0.0);
            // Eq. 2: L = Ft(eta, N.V) B(xo) / pi, B for Id = 1 scaled per channel.
            if (subsurface) {
                const glm::dvec3 xo =
                    (rays.eye() + double(front.distance) * direction) * scale;
                colour += fresnel_transmittance(material.eta, n_dot_v) * id *
                          integrator.radiosity(xo) / kPi;
            }
            if (ambient) colour += ambient_term(p, scene.light, n_dot_v, surface.ao);
            if (tone_map) colour = reinhard(colour, p.tone_key, average);
            if (has_specular_term(p, scene)) {
                const glm::dvec3 n_eye = glm::normalize(rays.normal_matrix() * n_object);
                colour += blinn_phong(p, scene.light, n_eye);
            }
            return colour;
        });
}

Image render_reference_with_error(const Scene& scene, const IntegratorQuality& quality,
                                  ReferenceError& error) {
    const Image coarse = render_reference(scene, quality);
    Image fine = render_reference(scene, quality.halved());
    error = reference_error(coarse, fine);
    return fine;
}

}  // namespace lucent::dipole
