// CPU reference of the thick_texture technique, independent of the pyramids and the GL
// passes (the thesis's ground truth, Sec. 4.2): per pixel n x n stratified rays (fixed
// jitter per pixel); each is cast with Embree through every sheet layer; at a hit the uv
// and tangent frame are interpolated with Embree's barycentrics, and the 2D
// Amanatides-Woo walk over the texel grid decides top (c1), wall (c2) or through (the
// next layer, finally the backdrop). The pixel is the mean of its rays.
#include <cmath>

#include "renderer/cpu/pixel_rays.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {
namespace {

struct Frame {
    glm::dvec2 uv;
    glm::dvec3 normal, tangent, bitangent;
};

// Interpolated uv, N and T at a hit, re-orthonormalised as the shader does.
Frame frame_at(const Mesh& mesh, const RayHit& hit) {
    const glm::uvec3 tri = mesh.triangles[hit.triangle];
    const double u = hit.barycentric.x, v = hit.barycentric.y, w = 1.0 - u - v;
    const auto mix3 = [&](auto a, auto b, auto c) { return w * a + u * b + v * c; };
    Frame f;
    f.uv = mix3(glm::dvec2(mesh.uvs[tri.x]), glm::dvec2(mesh.uvs[tri.y]),
                glm::dvec2(mesh.uvs[tri.z]));
    glm::dvec3 n = mix3(glm::dvec3(mesh.normals[tri.x]), glm::dvec3(mesh.normals[tri.y]),
                        glm::dvec3(mesh.normals[tri.z]));
    n = glm::dot(n, n) > 1e-30 ? glm::normalize(n) : glm::dvec3(hit.geometric_normal);
    const glm::dvec4 t4 =
        mix3(glm::dvec4(mesh.tangents[tri.x]), glm::dvec4(mesh.tangents[tri.y]),
             glm::dvec4(mesh.tangents[tri.z]));
    glm::dvec3 t = glm::dvec3(t4) - n * glm::dot(n, glm::dvec3(t4));
    if (glm::dot(t, t) < 1e-20)
        t = std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0))
                                : glm::cross(n, glm::dvec3(0, 1, 0));
    t = glm::normalize(t);
    f.normal = n;
    f.tangent = t;
    f.bitangent = (t4.w < 0.0 ? -1.0 : 1.0) * glm::cross(n, t);
    return f;
}

double jitter(int x, int y, int k) {
    std::uint64_t h = std::uint64_t(x) * 0x9e3779b97f4a7c15ull ^
                      std::uint64_t(y) * 0xc2b2ae3d27d4eb4full ^
                      std::uint64_t(k) * 0x165667b19e3779f9ull;
    h = (h ^ (h >> 31)) * 0xbf58476d1ce4e5b9ull;
    h ^= h >> 29;
    return double(h >> 11) * 0x1.0p-53;
}

}  // namespace

Image render_reference(const Scene& scene) {
    require_uvs(*scene.mesh);
    const Params p = params(scene);
    const TexelGrid& grid = scene_texture(p);
    const Mesh& mesh = *scene.mesh;
    const RayCaster caster(mesh);
    const PixelRays rays(scene.camera, scene.width, scene.height);
    // Rays are cast against the unrotated mesh: the sheet's rotation moves the ray.
    const glm::dmat4 inverse_model = glm::inverse(model_matrix(scene, p));
    const glm::dmat3 view_rotation(rays.view());
    const glm::dvec3 eye_object = glm::dvec3(inverse_model * glm::dvec4(rays.eye(), 1.0));
    const int n = std::max(1, int(std::lround(std::sqrt(double(p.reference_rays)))));
    const double density = p.texel_density;
    const glm::dvec3 c2 = p.wall_colour;

    Image image(scene.width, scene.height);
    for_each_row_parallel(scene.height, [&](int row) {
        for (int x = 0; x < scene.width; ++x) {
            glm::dvec3 sum(0.0);
            for (int sy = 0; sy < n; ++sy)
                for (int sx = 0; sx < n; ++sx) {
                    const int k = sy * n + sx;
                    const double ox = (sx + jitter(x, row, 2 * k)) / n;
                    const double oy = (sy + jitter(x, row, 2 * k + 1)) / n;
                    const glm::dvec3 d = rays.direction_at(x, row, ox, oy);
                    const glm::dvec3 d_object = glm::dmat3(inverse_model) * d;
                    glm::dvec3 colour(0.0);
                    bool behind = true;  // nothing stopped the ray yet
                    for (const RayHit& hit :
                         caster.hits(glm::vec3(eye_object), glm::vec3(d_object), 16)) {
                        const Frame f = frame_at(mesh, hit);
                        const glm::dvec3 local(glm::dot(d_object, f.tangent),
                                               glm::dot(d_object, f.bitangent),
                                               glm::dot(d_object, f.normal));
                        const glm::dvec2 r = scaled_ray(local, p.thickness, 1e4);
                        glm::ivec2 texel;
                        const SlabHit what = trace_slab(grid, f.uv * density, r, texel);
                        if (what == SlabHit::through) continue;
                        colour = what == SlabHit::top
                                     ? glm::dvec3(grid.colour_at(texel.x, texel.y))
                                     : c2;
                        behind = false;
                        break;
                    }
                    if (behind) colour = backdrop_colour(p, scene, view_rotation * d);
                    sum += colour;
                }
            // Alpha: the sheet's coverage at the pixel centre, as the GL composite.
            const glm::dvec3 centre = glm::dmat3(inverse_model) * rays.direction(x, row);
            const bool covered =
                caster.first_hit(glm::vec3(eye_object), glm::vec3(centre)).has_value();
            image.set(x, row,
                      glm::vec4(glm::vec3(sum / double(n * n)), covered ? 1.0f : 0.0f));
        }
    });
    return image;
}

}  // namespace lucent::thick_texture
