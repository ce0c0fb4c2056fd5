#version 450 core
// HTSM radiance (Shopf Table 4.1 and Sec. 4.3.5, with the decisions of README.md):
//   L = Tc (1/n) sum_i Ebar_i w(tau_i) f(mu_i) + [N.L > 0][lit] (Kd Id N.L + ks Is (N.H)^m)
//   tau_i = D_i + alpha_i, D_i = |(END_i - START) * e| / Phi,
//   alpha_i = kappa (D_i / S) sum_k rho(START + (k + 1/2)/S (END_i - START)),
//   w = max(0, 2 - tau / Td), f = Henyey-Greenstein with f(1) = 1 (table),
//   mu_i = dir_i . -N, dir_i = normalize(d_i + max(0, eps_d - |d_i|) l).
// The same equations as renderer/techniques/htsm/reference.cpp (exact footprints there).
// DEFERRED: a full-screen pass over the surface a `surface` pass stored, each covered
// pixel lit once instead of every rasterised fragment (the same floats, the same colour).
#include "techniques/shaders/surface_inputs.glsl"
#include "techniques/shaders/blinn_phong.glsl"
uniform vec3 u_light_direction;  // eye space, towards the light
uniform vec3 u_background;
layout(location = 0) out vec4 o_colour;

#ifdef WITH_TRANSPORT
uniform sampler2D htsm_irradiance;  // rgb E, mips: box means
uniform sampler2D htsm_texcoord;    // rgb t * coverage, a = coverage
uniform vec3 u_box_min;
uniform vec3 u_box_extent;
uniform float u_inv_phi;
uniform vec3 u_light_centre;
uniform vec3 u_light_right;
uniform vec3 u_light_up;
uniform vec3 u_to_light;
uniform float u_plane_size;  // 2 R_L
uniform float u_eps_d;
uniform vec3 u_transport_colour;
uniform float u_transport_distance;
uniform float u_kappa;
uniform vec4 u_pattern[HTSM_SAMPLES];  // xy: offset (object units), z: lod
#ifdef DENSITY_VOLUME
uniform sampler3D htsm_density;
#else
uniform float u_rho0;
#endif
#ifdef WITH_PHASE
uniform sampler2D htsm_phase;
uniform float u_phase_size;
#endif
#endif
#ifdef WITH_SURFACE
uniform sampler2D light_depth;
uniform mat4 u_light_view_projection;
uniform vec3 u_diffuse_colour;  // wd Kd Id
uniform vec3 u_specular;        // ks Is
uniform float u_shininess;
uniform float u_shadow_offset;
uniform float u_depth_bias;
#endif

void main() {
    Surface surface;
    if (!read_surface(surface)) {
        o_colour = vec4(u_background, 0.0);  // no surface: the clear colour
        return;
    }
    vec3 n = normalize(surface.normal_object);
    vec3 colour = vec3(0.0);
#ifdef WITH_TRANSPORT
    // The visible point's light-image coordinate and 3-D texture coordinate (START).
    vec3 rel = surface.position_object - u_light_centre;
    vec2 uv = vec2(dot(rel, u_light_right), dot(rel, u_light_up)) / u_plane_size + 0.5;
    vec3 start = (surface.position_object - u_box_min) / u_box_extent;
    vec3 sum = vec3(0.0);
    for (int i = 0; i < HTSM_SAMPLES; ++i) {
        // Sec. 4.3.1: the sample's footprint, read at its ring's mip level.
        vec2 uv_i = uv + u_pattern[i].xy / u_plane_size;
        if (any(lessThan(uv_i, vec2(0.0))) || any(greaterThan(uv_i, vec2(1.0)))) continue;
        vec4 t = textureLod(htsm_texcoord, uv_i, u_pattern[i].z);
        if (t.a < 1e-4) continue;
        vec3 end_point = t.rgb / t.a;
        vec3 e = textureLod(htsm_irradiance, uv_i, u_pattern[i].z).rgb;
        // Sec. 4.3.2: the ray from the visible point to the lit surface, in Phi.
        vec3 d = (end_point - start) * u_box_extent;
        float len = length(d);
        float ray = len * u_inv_phi;
#ifdef DENSITY_VOLUME
        float density = 0.0;
        for (int k = 0; k < HTSM_STEPS; ++k)
            density += texture(htsm_density,
                               start + (float(k) + 0.5) / float(HTSM_STEPS) *
                                           (end_point - start)).r;
        float tau = ray + u_kappa * ray * density / float(HTSM_STEPS);
#else
        float tau = ray * (1.0 + u_kappa * u_rho0);
#endif
        float w = max(0.0, 2.0 - tau / u_transport_distance);
#ifdef WITH_PHASE
        // Sec. 4.3.4: mu to -N; eps_d keeps the direction defined on lit points.
        vec3 dir = normalize(d + max(0.0, u_eps_d - len) * u_to_light);
        float u = 0.5 * clamp(dot(dir, -n), -1.0, 1.0) + 0.5;
        float f = texture(htsm_phase, vec2((0.5 + u * (u_phase_size - 1.0)) / u_phase_size, 0.5)).r;
#else
        float f = 1.0;
#endif
        sum += e * (w * f);
    }
    colour += u_transport_colour * sum / float(HTSM_SAMPLES);
#endif
#ifdef WITH_SURFACE
    // Diffuse and specular where N.L > 0 and the light view sees the point.
    vec3 n_eye = normalize(surface.normal_eye);
    float n_dot_l = dot(n_eye, u_light_direction);
    if (n_dot_l > 0.0) {
        vec3 lifted = surface.position_object + u_shadow_offset * n;
        vec4 clip = u_light_view_projection * vec4(lifted, 1.0);
        vec3 w = clip.xyz / clip.w * 0.5 + 0.5;
        float stored = texture(light_depth, w.xy).r;
        if (w.z - u_depth_bias <= stored) {
            float lobe = blinn_phong_lobe(n_eye, u_light_direction, u_shininess);
            colour += u_diffuse_colour * n_dot_l + u_specular * lobe;
        }
    }
#endif
    o_colour = vec4(colour, 1.0);
}
