#version 450 core
// Shading with the thesis's lighting equation (Eq. 3.6), in linear floating point:
//   colour = a*ka*Kd*Ia + wd*Kd*Id*max(N.L,0) + ws*ks*Is*max(N.H,0)^n   (only where N.L > 0)
//          + wb*(1 - t)^r*(Kd + Kb)
// Terms whose weight is zero are compiled out by the planner (WITH_AMBIENT_OCCLUSION,
// WITH_BACKLIGHT), never branched on here. DEFERRED: a full-screen pass that lights the
// front layer's stored surface once per pixel (front_surface.frag) instead of every
// rasterised fragment; the inputs are the same floats, so is the colour.
#ifdef DEFERRED
uniform sampler2D front_depth;    // window depth of the front layer; 1 = no surface
uniform sampler2D front_surface;  // interpolated eye-space normal, AO
#else
in vec3 v_normal_eye;
#ifdef WITH_AMBIENT_OCCLUSION
in float v_ambient_occlusion;
#endif
#endif
#ifdef WITH_AMBIENT_OCCLUSION
uniform float u_ambient;
uniform vec3 u_light_ambient;
#endif
// x^e with x^0 = 1 (also for x = 0) and negative bases treated as 0: GLSL's pow is
// undefined there.
float power(float x, float e) {
    if (e == 0.0) return 1.0;
    return x <= 0.0 ? 0.0 : pow(x, e);
}
#include "techniques/shaders/blinn_phong.glsl"

#ifdef WITH_BACKLIGHT
uniform float u_near;
uniform float u_far;
uniform float u_diameter;
uniform float u_backlight;
uniform float u_thickness_exponent;
uniform float u_diffuse_weight;

// Eq. 3.3: window depth -> positive eye-space distance.
float eye_depth(float window_depth) {
    float ndc = 2.0 * window_depth - 1.0;
    return 2.0 * u_near * u_far / (u_far + u_near - ndc * (u_far - u_near));
}

// Thickness over the bounding-sphere diameter (Eq. 3.4), in [0, 1], from the window depths
// of the two layers. No second layer (open mesh, clipped back) counts as the full
// diameter: t = 1.
float thickness(float front, float back) {
    if (back >= 1.0 || !(u_diameter > 0.0)) return 1.0;
    float t = (eye_depth(back) - eye_depth(front)) / u_diameter;
    return clamp(t, 0.0, 1.0);
}

// Eq. 3.10: wb * (1 - t)^r * (Kd + Kb).
vec3 backlight_term(float front, float back, vec3 albedo) {
    return u_backlight * power(1.0 - thickness(front, back), u_thickness_exponent) *
           (albedo + vec3(u_diffuse_weight));
}

// The second layer's window depth (1 = none): smoothed by an earlier pass, or, with
// SMOOTH_IN_SHADE, unsmoothed and smoothed here per fragment (the same operations, so the
// same floats, without a full-screen pass).
uniform sampler2D back_depth;
#ifdef SMOOTH_IN_SHADE
#include "techniques/empirical/shaders/smoothing.glsl"
uniform float u_falloff;
#endif
#endif
uniform vec3 u_albedo;
uniform float u_diffuse_contribution;
uniform float u_specular_contribution;
uniform float u_specular;
uniform float u_shininess;
uniform vec3 u_light_diffuse;
uniform vec3 u_light_specular;
uniform vec3 u_light_direction;  // unit, towards the light, eye space
layout(location = 0) out vec4 out_colour;

void main() {
#ifdef DEFERRED
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float front = texelFetch(front_depth, pixel, 0).r;
    if (front >= 1.0) discard;  // no surface: the clear colour stays, as when rasterising
    vec4 surface = texelFetch(front_surface, pixel, 0);
    vec3 normal_eye = surface.xyz;
    float ambient_occlusion = surface.w;
#else
    float front = gl_FragCoord.z;
    vec3 normal_eye = v_normal_eye;
#ifdef WITH_AMBIENT_OCCLUSION
    float ambient_occlusion = v_ambient_occlusion;
#endif
#endif
    // Unit normal; a zero-length one (degenerate input) faces the viewer.
    float length2 = dot(normal_eye, normal_eye);
    vec3 n = length2 > 1e-30 ? normal_eye * inversesqrt(length2) : vec3(0.0, 0.0, 1.0);
    vec3 l = u_light_direction;
    vec3 colour = vec3(0.0);

#ifdef WITH_AMBIENT_OCCLUSION
    // Ambient term (Eq. 3.7): a * ka * Kd * Ia
    colour += ambient_occlusion * u_ambient * u_albedo * u_light_ambient;
#endif

    // Diffuse and specular terms (Eqs. 3.8-3.9), only where N.L > 0. The half vector uses
    // a viewer at infinity (0,0,1), as OpenGL's fixed-function halfVector.
    float n_dot_l = dot(n, l);
    if (n_dot_l > 0.0) {
        colour += u_diffuse_contribution * u_albedo * u_light_diffuse * n_dot_l;
        colour += u_specular_contribution * u_specular * u_light_specular *
                  blinn_phong_lobe(n, l, u_shininess);
    }

#ifdef WITH_BACKLIGHT
    // Thickness term (Eq. 3.10): wb * (1 - t)^r * (Kd + Kb)
#ifdef SMOOTH_IN_SHADE
    float back = smoothed_depth(back_depth, ivec2(gl_FragCoord.xy), u_falloff);
#else
    float back = texelFetch(back_depth, ivec2(gl_FragCoord.xy), 0).r;
#endif
    colour += backlight_term(front, back, u_albedo);
#endif
    out_colour = vec4(colour, 1.0);
}
