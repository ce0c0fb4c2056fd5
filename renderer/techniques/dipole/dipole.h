#pragma once
// The dipole technique: Chang et al.'s texture-space importance sampling of Jensen's
// dipole BSSRDF (seed 001), with its hybrid local/global split, in physical units. What
// the knobs, the GL passes and the CPU reference share. See README.md beside this file.
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/image_compare.h"
#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"
#include "renderer/techniques/deferred_surface.h"
#include "renderer/techniques/dipole/integrator.h"
#include "renderer/techniques/dipole/scattering.h"

namespace lucent::dipole {

struct Params {
    std::string material = "skin1";              // a JMLH01 preset or "custom"
    glm::dvec3 sigma_a{0.032, 0.17, 0.48};       // mm^-1, [0, 100]; custom only
    glm::dvec3 sigma_s_prime{0.74, 0.88, 1.01};  // mm^-1, [0, 1000]; custom only
    double eta = 1.3;                            // [1, 2]; custom only (presets: 1.3)
    double model_size = 10.0;                    // mm: the mesh's bounding-box diagonal
    int samples = 256;                           // N, [1, 65536]
    int atlas_resolution = 512;                  // A: 256, 512, 1024, 2048
    bool hybrid = false;                         // Sec. 4 local/global split
    int rings = 20;                              // L, [1, 32]
    int ring_samples = 20;                       // C, [1, 32]
    double importance_bound = 0.1;               // c, mm^-1
    double hybrid_k = 1.5;                       // K, mm^-1
    int light_map_resolution = 512;              // 256, 512, 1024
    int sample_seed = 0;                         // stratification offset
    std::string tone_map = "none";               // none | reinhard
    double tone_key = 0.18;                      // Reinhard key a
    double specular = 0.5;                       // ks (shared knob)
    double shininess = 64.0;                     // n (shared knob)
    double ambient = 0.3;                        // ka (shared knob)
    int ao_rays = 320;
    bool operator==(const Params&) const = default;
};

const std::vector<Knob>& knobs();
Params params(const Scene& scene);
// The `material` knob's choices: every preset's name, then "custom".
std::vector<std::string> material_choices();
// The preset's values, or the custom sigma_a, sigma_s' and eta.
Material material_of(const Params& p);
// mm per mesh unit: model_size / (the mesh's bounding-box diagonal), 1 for a point mesh.
double model_scale(const Mesh& mesh, double model_size_mm);
// Unit direction towards the key light in mesh (object) space.
glm::dvec3 light_in_object_space(const Scene& scene);

// Which terms can change the image (planner and reference agree on these).
bool has_subsurface_term(const Params& p, const Scene& scene);  // Id != 0, some Rd != 0
bool has_specular_term(const Params& p, const Scene& scene);
bool has_ambient_term(const Params& p, const Scene& scene);

// The display-side operations shared by GL and the reference.
//   Reinhard (the operator of the DirectX HDRLighting sample the paper cites, not the
//   inverted formula it prints): s = a L / L_avg per channel, colour = s / (1 + s).
glm::dvec3 reinhard(glm::dvec3 radiance, double key, double average_luminance);
// L_avg for the tone map: the mean outgoing radiance over the surface if all flux came
// back out, Y(Id * Rd_tot) * Phi / (pi * total area) (README.md: why, and the paper's
// unit-dependent Phi).
double tone_map_average(const Params& p, const Scene& scene, double flux_per_id,
                        double total_area_mm2);
// Blinn-Phong as the empirical technique: ks Is max(N.H, 0)^n where N.L > 0, H from the
// light and a viewer at infinity (eye space).
glm::dvec3 blinn_phong(const Params& p, const Light& light, glm::dvec3 n_eye);
// Ambient: ka Ia Kd AO with Kd = Ft(eta, N.V) * mean Ft * Rd_tot, the dipole's
// response to uniform irradiance on a flat slab.
glm::dvec3 ambient_term(const Params& p, const Light& light, double n_dot_v, double ao);

// CPU reference (reference.cpp): Embree primary rays, ScatteringIntegrator for B.
struct ReferenceStats {
    std::size_t cells = 0;
    double cell_size_mm = 0.0;
    double flux = 0.0;  // Phi / Id, mm^2
};
Image render_reference(const Scene& scene, const IntegratorQuality& quality,
                       ReferenceStats* stats = nullptr);
// The reference's own error (core/image_compare.h reference_error) between quality and
// quality.halved(); returns the halved image.
Image render_reference_with_error(const Scene& scene, const IntegratorQuality& quality,
                                  ReferenceError& error);

// `translucency` lights each covered pixel once from the stored surface (deferred, what
// the technique plans; techniques/deferred_surface.h), or every rasterised fragment
// (forward: for the test that the two agree bit for bit).
void add_passes(const Scene& scene, PlanBuilder& plan,
                SurfaceShading shading = SurfaceShading::deferred);

}  // namespace lucent::dipole
