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
    const int w = scene.width, h = scene.height;
    const PixelRays rays(scene.camera, w, h);

    Image image(w, h);
    for_each_row_parallel(h, [&](int row) {
        for (int x = 0; x < w; ++x) {
            const glm::dvec3 direction = rays.direction(x, row);
            const std::optional<RayHit> front = rays.front_hit(caster, direction);
            if (!front) {
                image.set(x, row, glm::vec4(scene.background, 0.0f));
                continue;
            }
            const SurfaceSample surface = interpolate_at(mesh, *front, vertex_ao);
            const double n2 = glm::dot(surface.normal, surface.normal);
            const glm::dvec3 n_object =
                n2 > 1e-30 ? surface.normal / std::sqrt(n2) : glm::dvec3(0.0, 0.0, 1.0);
            const double n_dot_v = std::max(glm::dot(n_object, -direction), 0.0);
            glm::dvec3 colour(0.0);
            // Eq. 2: L = Ft(eta, N.V) B(xo) / pi, B for Id = 1 scaled per channel.
            if (subsurface) {
                const glm::dvec3 xo =
                    (rays.eye() + double(front->distance) * direction) * scale;
                colour += fresnel_transmittance(material.eta, n_dot_v) * id *
                          integrator.radiosity(xo) / kPi;
            }
            if (ambient) colour += ambient_term(p, scene.light, n_dot_v, surface.ao);
            if (tone_map) colour = reinhard(colour, p.tone_key, average);
            if (has_specular_term(p, scene)) {
                const glm::dvec3 n_eye = glm::normalize(rays.normal_matrix() * n_object);
                colour += blinn_phong(p, scene.light, n_eye);
            }
            image.set(x, row, glm::vec4(glm::vec3(colour), 1.0f));
        }
    });
    return image;
}

Image render_reference_with_error(const Scene& scene, const IntegratorQuality& quality,
                                  ReferenceError& error) {
    const Image coarse = render_reference(scene, quality);
    Image fine = render_reference(scene, quality.halved());
    double sum2 = 0.0, ref2 = 0.0, worst = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < fine.height; ++y)
        for (int x = 0; x < fine.width; ++x) {
            const glm::vec4 a = coarse.at(x, y), b = fine.at(x, y);
            if (a.a == 0.0f || b.a == 0.0f) continue;
            for (int c = 0; c < 3; ++c) {
                const double d = double(a[c]) - double(b[c]);
                sum2 += d * d;
                ref2 += double(b[c]) * double(b[c]);
                worst = std::max(worst, std::abs(d));
            }
            ++count;
        }
    error = {};
    if (count > 0) {
        error.rms = std::sqrt(sum2 / (3.0 * count));
        error.max = worst;
        error.relative_rms = ref2 > 0.0 ? std::sqrt(sum2 / ref2) : 0.0;
    }
    return fine;
}

}  // namespace lucent::dipole
