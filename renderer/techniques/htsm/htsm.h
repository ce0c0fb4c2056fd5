#pragma once
// The htsm technique: Shopf's heterogeneous translucent shadow maps (seed 003, after
// Dachsbacher and Stamminger's TSM): light-view images of Fresnel-transmitted irradiance
// and 3-D texture coordinate with box-filtered mips, a hierarchical pattern of n rays
// from each visible point to the lit surface, S steps through the density volume per
// ray, a phase table, transport colour Tc and distance Td. What the knobs, the GL passes
// and the CPU reference share; README.md beside this file states every decision.
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/image_compare.h"
#include "renderer/core/knobs.h"
#include "renderer/core/light_view.h"
#include "renderer/core/scene.h"
#include "renderer/techniques/deferred_surface.h"

namespace lucent::htsm {

struct Params {
    int samples = 5;           // knob `rays`: n = 1 + 4K rays: 1, 5, 9, 13 (Fig. 5.7/5.9)
    int steps = 5;             // S midpoint steps per ray, [1, 64]
    int light_map_size = 256;  // W_L: 64 .. 1024, a power of two
    bool light_mips = true;    // rings read their footprint's mip level (off: lod 0)
    int density_resolution = 64;   // R of generated volumes: 16, 32, 64, 128
    int phase_table_size = 256;    // N_f: 16, 64, 256, 1024
    double pattern_radius = 0.02;  // r1, first ring radius, fraction of Phi
    glm::dvec3 transport_colour{1.0, 0.55, 0.3};  // Tc, linear rgb [0, 4]
    double transport_distance = 0.25;             // Td, fraction of Phi, [1e-3, 10]
    double density_scale = 2.0;  // kappa, optical depth per Phi at rho = 1, [0, 1000]
    double phase_g = 0.5;        // Henyey-Greenstein g, [0, 0.8]
    double ior = 1.3;            // eta for Schlick's Fresnel, [1, 2]
    glm::dvec3 albedo{0.8, 0.55, 0.35};  // Kd of the diffuse term (the shared default)
    double diffuse = 0.2;                // wd, [0, 10]
    double specular = 0.5;               // ks (the shared default)
    double shininess = 64.0;             // n (the shared default)
    bool operator==(const Params&) const = default;
};

const std::vector<Knob>& knobs();
Params params(const Scene& scene);

// The object's box and light geometry, shared by the GL uniforms and the reference.
struct Geometry {
    glm::dvec3 box_min{0.0}, box_extent{1.0};  // AABB, each extent >= 1e-3 Phi
    double phi = 1.0;                          // bounding-sphere diameter (Lucent's unit)
    LightView light;
    glm::dvec3 to_light{0, 0, 1};  // object space, unit
    double texel = 1.0;            // h_L = 2 R_L / W_L, object units
};
Geometry geometry(const Scene& scene, const Params& p);

// The hierarchical pattern: offsets (object units along the light image's right, up)
// and mip levels lambda = clamp(log2(rho_k / h_L), 0, log2 W_L); sample 0 is the centre.
struct PatternSample {
    glm::dvec2 offset{0.0};
    double lod = 0.0;
};
std::vector<PatternSample> pattern(const Params& p, const Geometry& g);

// Schlick's Fresnel reflectance for the cosine c; 0 for eta = 1.
double schlick(double eta, double c);
// Henyey-Greenstein normalised to f(1) = 1 (README: why); 1 for g = 0.
double phase(double g, double mu);
// w(tau) = max(0, 2 - tau / Td) (Table 4.1, clamped).
double transport_weight(double tau, double td);

// Which terms can change the image (planner and reference agree on these).
bool has_transport(const Params& p, const Scene& scene);  // Tc != 0 and Id != 0
bool has_surface(const Params& p, const Scene& scene);    // diffuse or specular
// The density is the same everywhere (a constant volume, contrast 0 or kappa = 0):
// tau = (1 + kappa rho0) D in closed form, no march, no volume upload.
bool density_is_constant(const Params& p, const Scene& scene);
double constant_density(const Scene& scene);  // rho0 (0 without a volume)

// The CPU reference (reference.cpp): Embree light image at `oversample` x W_L with
// summed-area tables for exact box footprints, an Embree camera ray per pixel, a march of
// `steps` midpoint steps through the same voxels, exact phase, Embree shadow rays.
struct ReferenceQuality {
    int oversample = 8;  // F: light-image rays per W_L texel along each axis
    int steps = 1024;    // S_ref
    ReferenceQuality halved() const { return {oversample / 2, steps / 2}; }
};
Image render_reference(const Scene& scene, const ReferenceQuality& quality);
// Renders at `quality` and at quality.halved(): the difference is the reference's own
// error estimate (core/image_compare.h reference_error); returns the finer image.
Image render_reference_with_error(const Scene& scene, const ReferenceQuality& quality,
                                  ReferenceError& error);

// `shade` lights each covered pixel once from the stored surface (deferred, what the
// technique plans; techniques/deferred_surface.h), or every rasterised fragment
// (forward: for the test that the two agree bit for bit).
void add_passes(const Scene& scene, PlanBuilder& plan,
                SurfaceShading shading = SurfaceShading::deferred);

// Texture fetches per covered pixel of the shade pass as planned (pruned): per ray the
// texcoord and irradiance, S density steps (a march), a phase lookup (g != 0); one
// shadow-map read (surface terms). The thesis's "45 for n = 9" counts density only;
// the full count at S = 5 is n (S + 3) + 1.
int fetches_per_pixel(const Scene& scene);

}  // namespace lucent::htsm
