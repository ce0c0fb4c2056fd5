#pragma once
// How close each real-time technique comes to the path-traced truth (issue 28): the
// error of an image against the truth as displayed (mean and 95th-percentile Delta E00
// on the object's pixels, and linear RMSE), the technique's knobs fitted to the truth
// (those it shares with the truth by name, e.g. the dipole's material, taken directly;
// its Technique::fidelity_fit knobs searched by NLopt's BOBYQA within a stated budget),
// its frame time, and the same along its quality knobs. `lucent bench fidelity` prints
// and plots it.
#include <functional>
#include <string>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"
#include "renderer/core/technique.h"
#include "renderer/gl/frame_executor.h"

namespace lucent::stimuli {

struct ImageError {
    double mean_delta_e = 0.0;  // CIEDE2000 of the sRGB-displayed images
    double p95_delta_e = 0.0;
    // sqrt(mean Delta E00^2): what the fit minimises (smooth where the error reaches 0,
    // so BOBYQA's quadratic model fits it; the mean of |Delta E| has a kink there)
    double rms_delta_e = 0.0;
    double rmse = 0.0;       // linear rgb
    std::size_t pixels = 0;  // object pixels of either image
};
// `image` against `truth` (same size) over the pixels either covers (alpha > 0.5).
ImageError image_error(const Image& image, const Image& truth);

struct FitOptions {
    int max_evaluations = 60;  // renders per technique's fit
    // Called after each evaluation with (done, max_evaluations); may be empty.
    std::function<void(int, int)> progress;
};

struct QualityPoint {
    std::string knob, value;
    ImageError error;
    double frame_ms = 0.0;
};

struct TechniqueFit {
    std::string technique;
    std::string refused;  // why the technique cannot render this scene; empty: fitted
    std::vector<KnobAssignment> taken;   // from the truth, by shared knob name
    std::vector<KnobAssignment> fitted;  // found by the optimiser
    ImageError start_error;              // at the technique's defaults (+ taken)
    ImageError error;                    // at the fitted values
    double frame_ms = 0.0;               // GPU time of a frame, bakes excluded
    int evaluations = 0;
    std::vector<QualityPoint> quality;  // along each quality knob, at the fitted values
    Image image;                        // at the fitted values
};

// The scene `technique` draws of the truth's scene: the same mesh, size and view, the
// truth's values of every knob the technique has by the same name (validated), and
// `settings` over them. Throws KnobError or MeshError when the technique refuses it.
Scene scene_like(const Scene& truth_scene, const Technique& technique,
                 const std::vector<KnobAssignment>& settings,
                 std::vector<KnobAssignment>* taken = nullptr);

// Fits `technique` to `truth` (the image of `truth_scene`) with a GL executor whose
// context is current.
TechniqueFit fit_to_truth(gl::FrameExecutor& executor, const Technique& technique,
                          const Scene& truth_scene, const Image& truth,
                          const FitOptions& options = {});

// GPU milliseconds of one frame of `scene` (median of `frames`, bakes excluded), each
// frame on a fresh executor so no pass is reused.
double frame_milliseconds(const Scene& scene, int frames = 3);

}  // namespace lucent::stimuli
