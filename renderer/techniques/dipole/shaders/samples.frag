#version 450 core
// Texture-space importance sampling (Chang et al. Sec. 3, Fig. 2b): fragment k of the
// sqrt(N) x sqrt(N) target descends the irradiance mip pyramid with y_k = (k + xi)/N,
// at each level normalising by the four children's own sum and never entering a
// zero-mass child, and writes the chosen texel's position (mm) with w = 1 (w = 0: no
// sample, k >= N or no irradiance). Same rule as descend() in atlas.cpp.
uniform sampler2D irradiance;      // full mip chain (box means)
uniform sampler2D atlas_position;
uniform int u_sample_count;        // N
uniform int u_sample_side;         // the target's width
uniform int u_top_level;           // log2(atlas resolution)
uniform float u_offset;            // xi
out vec4 o_sample;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    int k = pixel.y * u_sample_side + pixel.x;
    float total = texelFetch(irradiance, ivec2(0), u_top_level).r;
    if (k >= u_sample_count || !(total > 0.0)) {
        o_sample = vec4(0.0);
        return;
    }
    float y = (float(k) + u_offset) / float(u_sample_count);
    ivec2 at = ivec2(0);
    for (int level = u_top_level - 1; level >= 0; --level) {
        float child[4];
        float sum = 0.0;
        int last_nonzero = -1;
        for (int q = 0; q < 4; ++q) {
            child[q] = texelFetch(irradiance, 2 * at + ivec2(q & 1, q >> 1), level).r;
            sum += child[q];
            if (child[q] > 0.0) last_nonzero = q;
        }
        if (last_nonzero < 0) { o_sample = vec4(0.0); return; }
        float target = y * sum;
        float before = 0.0;
        int pick = last_nonzero;
        for (int q = 0; q < 4; ++q) {
            if (child[q] > 0.0 && target < before + child[q]) { pick = q; break; }
            before += child[q];
        }
        if (pick == last_nonzero) {
            before = 0.0;
            for (int q = 0; q < pick; ++q) before += child[q];
        }
        y = clamp((target - before) / child[pick], 0.0, 0.99999994);
        at = 2 * at + ivec2(pick & 1, pick >> 1);
    }
    o_sample = vec4(texelFetch(atlas_position, at, 0).xyz, 1.0);
}
