// Depth-aware smoothing of the second layer (App. C.2.2, Eq. C.1), shared by
// smooth_depth.frag (its own pass) and shade.frag (SMOOTH_IN_SHADE). Weights are the
// thesis's 5x5 kernel (or a binomial 3x3, or 1x1 = copy), times a falloff that ignores
// samples whose window depth differs from the centre by `falloff` or more. Background samples (depth 1: no second
// layer) are skipped; a centre without a second layer stays 1. Edge texels repeat, as with
// clamp-to-edge sampling.
#ifndef KERNEL_SIZE
#define KERNEL_SIZE 5
#endif

#if KERNEL_SIZE == 5
const float kSmoothingWeights[25] = float[25](1, 4, 7, 4, 1, 4, 16, 26, 16, 4, 7, 26, 41,
                                              26, 7, 4, 16, 26, 16, 4, 1, 4, 7, 4, 1);
#elif KERNEL_SIZE == 3
const float kSmoothingWeights[9] = float[9](1, 2, 1, 2, 4, 2, 1, 2, 1);
#else
const float kSmoothingWeights[1] = float[1](1);
#endif

// The smoothed window depth at `centre` of `layer` (sampled with clamp-to-edge: the 5x5
// window is read with nine textureGather calls, each 2x2 texels, whose clamped footprint
// repeats edge texels as the integer clamp would).
float smoothed_depth(sampler2D layer, ivec2 centre, float falloff) {
    float d0 = texelFetch(layer, centre, 0).r;
    if (d0 >= 1.0) return 1.0;
    const int size = KERNEL_SIZE;
    float window[KERNEL_SIZE * KERNEL_SIZE];
#if KERNEL_SIZE == 5
    // A gather at a texel corner returns the 2x2 texels around it (w: lower left, z:
    // lower right, x: upper left, y: upper right); 3x3 gathers cover the 6x6 block from
    // centre - 2, of which the 5x5 window is used. One gather costs about one fetch on
    // llvmpipe, so this reads 9 times instead of 25 (same texels, same sums).
    vec2 texel = 1.0 / vec2(textureSize(layer, 0));
    for (int gj = 0; gj < 3; ++gj) {
        for (int gi = 0; gi < 3; ++gi) {
            ivec2 low = centre + ivec2(2 * gi - 2, 2 * gj - 2);
            vec4 g = textureGather(layer, (vec2(low) + 1.0) * texel);
            int x = 2 * gi, y = 2 * gj;
            window[y * size + x] = g.w;
            if (x + 1 < size) window[y * size + x + 1] = g.z;
            if (y + 1 < size) {
                window[(y + 1) * size + x] = g.x;
                if (x + 1 < size) window[(y + 1) * size + x + 1] = g.y;
            }
        }
    }
#else
    const int radius = KERNEL_SIZE / 2;
    ivec2 last = textureSize(layer, 0) - 1;
    for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i)
            window[j * size + i] =
                texelFetch(layer, clamp(centre + ivec2(i - radius, j - radius), ivec2(0),
                                        last), 0).r;
#endif
    float sum = 0.0;
    float total = 0.0;
    for (int k = 0; k < size * size; ++k) {
        float d = window[k];
        if (d >= 1.0) continue;
        // Eq. C.1: w = k_i * (1 - clamp(|d_i - d_0| / falloff, 0, 1))
        float w = kSmoothingWeights[k] * (1.0 - clamp(abs(d - d0) / falloff, 0.0, 1.0));
        sum += w * d;
        total += w;
    }
    // The centre always contributes its full weight, so total > 0.
    return sum / total;
}
