// Algorithm 3.1 (corrected) and the wide-hole fix on the CPU: the same equations the
// shader evaluates (shaders/thick.glsl), in double precision.
#include <algorithm>
#include <cmath>

#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {

glm::dvec2 scaled_ray(glm::dvec3 d, double thickness, double cap) {
    // Eq. 3.2.5 with z scaled to h: r = h (dT, dB) / |dN|, each magnitude capped so that
    // a grazing ray (dN -> 0) stays finite: m >= cap |dN| means "at least cap texels".
    const double dn = std::abs(d.z);
    const auto component = [&](double dt) {
        const double m = thickness * std::abs(dt);
        const double magnitude = m >= cap * dn ? (m > 0.0 ? cap : 0.0) : m / dn;
        return dt < 0.0 ? -magnitude : magnitude;
    };
    return {component(d.x), component(d.y)};
}

Fractions model_fractions(const TexelRecord& t, glm::dvec2 r) {
    // Steps 1-4: clamped magnitudes and the walls and triangles facing the ray.
    const double a = std::min(std::abs(r.x), 1.0), b = std::min(std::abs(r.y), 1.0);
    const double horizontal = r.x > 0.0 ? t.walls[3] : r.x < 0.0 ? t.walls[1] : 0.0;
    const double vertical = r.y > 0.0 ? t.walls[0] : r.y < 0.0 ? t.walls[2] : 0.0;
    double diagonal = 0.0;
    if (r.x > 0.0 && r.y > 0.0) diagonal = t.triangles[0];
    if (r.x < 0.0 && r.y > 0.0) diagonal = t.triangles[1];
    if (r.x < 0.0 && r.y < 0.0) diagonal = t.triangles[2];
    if (r.x > 0.0 && r.y < 0.0) diagonal = t.triangles[3];
    // Step 5 (Eqs. 3.4.1-3.4.2 per wall, plus the corner triangles).
    double occluded = horizontal * (a - a * b / 2.0) + vertical * (b - a * b / 2.0) +
                      diagonal * a * b / 2.0;
    // Wide-hole fix (our design of the thesis's Ch. 5 future work): per-axis escape terms
    // from the run-length histograms, combined for rectangular holes, replacing the
    // bin-0 (|r| <= 1) part the thesis already counts.
    const double hole = 1.0 - t.opaque;
    if (!t.bins[0].empty() && hole > 1e-12) {
        const auto& bx = t.bins[r.x > 0.0 ? 0 : 1];
        const auto& by = t.bins[r.y > 0.0 ? 2 : 3];
        double ax = 0.0, ay = 0.0;
        for (std::size_t k = 0; k < bx.size(); ++k) {
            if (r.x != 0.0) ax += bx[k] * std::clamp(std::abs(r.x) - double(k), 0.0, 1.0);
            if (r.y != 0.0) ay += by[k] * std::clamp(std::abs(r.y) - double(k), 0.0, 1.0);
        }
        const double ax0 = r.x != 0.0 ? bx[0] * a : 0.0,
                     ay0 = r.y != 0.0 ? by[0] * b : 0.0;
        occluded += (ax + ay - ax * ay / hole) - (ax0 + ay0 - ax0 * ay0 / hole);
    }
    // Step 6, clamped: never more than the holes, never negative.
    Fractions f;
    f.opaque = std::clamp(t.opaque, 0.0, 1.0);
    f.occluded = std::clamp(occluded, 0.0, 1.0 - f.opaque);
    f.transparent = std::max(0.0, 1.0 - f.opaque - f.occluded);
    return f;
}

}  // namespace lucent::thick_texture
