#version 450 core
// Depth-aware smoothing of the second layer (App. C.2.2, Eq. C.1). Weights are the
// thesis's 5x5 kernel (or a binomial 3x3, or 1x1 = copy), times a falloff that ignores
// samples whose window depth differs from the centre by u_falloff or more. Background
// samples (depth 1: no second layer) are skipped; a centre without a second layer stays 1.
#ifndef KERNEL_SIZE
#define KERNEL_SIZE 5
#endif
uniform sampler2D back_depth;
uniform float u_falloff;
layout(location = 0) out float out_depth;

#if KERNEL_SIZE == 5
const float kWeights[25] = float[25](1, 4, 7, 4, 1, 4, 16, 26, 16, 4, 7, 26, 41, 26, 7,
                                     4, 16, 26, 16, 4, 1, 4, 7, 4, 1);
#elif KERNEL_SIZE == 3
const float kWeights[9] = float[9](1, 2, 1, 2, 4, 2, 1, 2, 1);
#else
const float kWeights[1] = float[1](1);
#endif

void main() {
    ivec2 centre = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(back_depth, 0) - 1;
    float d0 = texelFetch(back_depth, centre, 0).r;
    if (d0 >= 1.0) {
        out_depth = 1.0;
        return;
    }
    const int radius = KERNEL_SIZE / 2;
    float sum = 0.0;
    float total = 0.0;
    for (int j = -radius; j <= radius; ++j) {
        for (int i = -radius; i <= radius; ++i) {
            // Edge texels repeat, as with clamp-to-edge sampling.
            float d = texelFetch(back_depth, clamp(centre + ivec2(i, j), ivec2(0), last), 0).r;
            if (d >= 1.0) continue;
            // Eq. C.1: w = k_i * (1 - clamp(|d_i - d_0| / falloff, 0, 1))
            float w = kWeights[(j + radius) * KERNEL_SIZE + (i + radius)] *
                      (1.0 - clamp(abs(d - d0) / u_falloff, 0.0, 1.0));
            sum += w * d;
            total += w;
        }
    }
    // The centre always contributes its full weight, so total > 0.
    out_depth = sum / total;
}
