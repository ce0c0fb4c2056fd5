#pragma once
// Error between two images of the same scene (GL vs CPU reference), as the tests and
// `lucent bench accuracy` measure it.
#include "renderer/core/image.h"

namespace lucent {

struct ImageErrorStats {
    double rmse = 0.0;  // root mean square over rgb values of the compared pixels
    double mean = 0.0;  // mean absolute difference over rgb values
    double p99 = 0.0;   // 99th percentile of the per-pixel largest channel difference
    double max = 0.0;
    std::size_t pixels = 0;  // pixels compared
};

// Compares rgb of equally sized images, skipping pixels within `band` pixels of a
// silhouette of either image (a neighbour with different coverage, alpha > 0.5), where
// rasterisation and ray casting legitimately disagree. band = 0 compares every pixel.
// Throws std::invalid_argument when the sizes differ.
ImageErrorStats compare_images(const Image& a, const Image& b, int band = 1);

// A CPU reference's estimate of its own error: the rgb differences between its images of
// one scene at two qualities, over the pixels both cover (alpha != 0). relative_rms is
// rms over the root mean square of the finer image's values (0 when that is 0).
struct ReferenceError {
    double rms = 0.0, max = 0.0, relative_rms = 0.0;
};
ReferenceError reference_error(const Image& coarse, const Image& fine);

}  // namespace lucent
