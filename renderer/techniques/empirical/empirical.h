#pragma once
// The empirical translucency technique (thesis ch. 3, appendices B-C): what its GL passes
// and its CPU reference share. See README.md beside this file for the equations.
#include <array>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/scene.h"
#include "renderer/techniques/deferred_surface.h"
#include "renderer/techniques/empirical/knobs.h"

namespace lucent::empirical {

// Depth-aware smoothing (App. C.2.2): samples differing from the centre by more than this
// (window depth units) get weight 0, linearly fading in below it (Eq. C.1).
inline constexpr double kSmoothingFalloff = 0.1;
// Integer kernel weights of the thesis's 5x5 kernel (1,4,7,16,26,41; the /26 cancels in
// the normalisation) and a binomial 3x3; row-major, symmetric.
// clang-format off
inline constexpr std::array<double, 25> kKernel5 = {1,  4,  7,  4, 1,
                                                    4, 16, 26, 16, 4,
                                                    7, 26, 41, 26, 7,
                                                    4, 16, 26, 16, 4,
                                                    1,  4,  7,  4, 1};
// clang-format on
inline constexpr std::array<double, 9> kKernel3 = {1, 2, 1, 2, 4, 2, 1, 2, 1};

// Peeling epsilon (App. B) in window depth: the thesis's 1e-6, raised to one depth
// quantum for 16-bit depth so a surface never peels itself.
double peel_epsilon(const std::string& depth_precision);
ResourceFormat depth_format(const std::string& depth_precision);

// Adds the technique's passes to `plan` (passes.cpp).
// `shading`: deferred (what the technique plans) lights the front layer once per pixel
// from the surface its front pass stored, where that gives the same image: peeled
// layers, the backlight on, 32f depth; elsewhere, and always with forward (for the test
// that the two agree), `shade` lights every rasterised fragment. The empirical technique
// stores its surface in the front-depth pass it needs anyway, not with shade_deferred().
void add_passes(const Scene& scene, PlanBuilder& plan,
                SurfaceShading shading = SurfaceShading::deferred);
// CPU reference with Embree (reference.cpp).
Image render_reference(const Scene& scene);

}  // namespace lucent::empirical
