#version 450 core
// Composites the peeled sheet layers front to back over the backdrop (premultiplied:
// C = sum_k prod_{m<k} (1 - A_m) C_k + prod (1 - A_k) backdrop). The backdrop is a plane
// perpendicular to the view axis at u_backdrop_distance, box-filtered over the pixel
// exactly (a checker is 1/2 + 1/2 s(x) s(y) with s a square wave, whose box mean is a
// difference of its triangle-wave integral), which the reference's many rays converge
// to. Alpha = the sheet's coverage at the pixel centre (for silhouette bands).
uniform sampler2D layer_0_colour;
uniform sampler2D layer_0_depth;
#if LAYERS > 1
uniform sampler2D layer_1_colour;
#endif
#if LAYERS > 2
uniform sampler2D layer_2_colour;
#endif
#if LAYERS > 3
uniform sampler2D layer_3_colour;
#endif
uniform vec3 u_pixel_scale;  // xy: backdrop-plane units per pixel
uniform vec3 u_viewport;     // xy: size in pixels
uniform int u_backdrop;      // 0 checker, 1 stripes, 2 plain
uniform vec3 u_backdrop_a;
uniform vec3 u_backdrop_b;
uniform float u_period;
out vec4 o_colour;

// Integral of the square wave s (+1 on even cells of width p) from 0 to x.
float square_integral(float x, float p) {
    float m = mod(x / p, 2.0);
    return p * (m <= 1.0 ? m : 2.0 - m);
}
float square_mean(float x0, float x1, float p) {
    return (square_integral(x1, p) - square_integral(x0, p)) / (x1 - x0);
}

vec3 backdrop() {
    if (u_backdrop == 2) return u_backdrop_a;
    vec2 lo = (gl_FragCoord.xy - 0.5 - 0.5 * u_viewport.xy) * u_pixel_scale.xy;
    vec2 hi = lo + u_pixel_scale.xy;
    float sx = square_mean(lo.x, hi.x, u_period);
    float s = u_backdrop == 1 ? sx : sx * square_mean(lo.y, hi.y, u_period);
    return 0.5 * (u_backdrop_a + u_backdrop_b) + 0.5 * s * (u_backdrop_a - u_backdrop_b);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 colour = vec3(0.0);
    float transmitted = 1.0;
    vec4 layer = texelFetch(layer_0_colour, pixel, 0);
    colour += transmitted * layer.rgb;
    transmitted *= 1.0 - layer.a;
#if LAYERS > 1
    layer = texelFetch(layer_1_colour, pixel, 0);
    colour += transmitted * layer.rgb;
    transmitted *= 1.0 - layer.a;
#endif
#if LAYERS > 2
    layer = texelFetch(layer_2_colour, pixel, 0);
    colour += transmitted * layer.rgb;
    transmitted *= 1.0 - layer.a;
#endif
#if LAYERS > 3
    layer = texelFetch(layer_3_colour, pixel, 0);
    colour += transmitted * layer.rgb;
    transmitted *= 1.0 - layer.a;
#endif
    colour += transmitted * backdrop();
    float covered = texelFetch(layer_0_depth, pixel, 0).r < 1.0 ? 1.0 : 0.0;
    o_colour = vec4(colour, covered);
}
