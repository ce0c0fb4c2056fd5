#version 450 core
// The dipole's radiance (Chang et al. Eq. 11) and what follows it:
//   L = Ft(eta, N.V) Id B(xo) / pi,
//   B = (Phi / N) sum_k Rd_g(|x_k - xo|)                      (global, Eq. 10)
//     + sum_j w_j phi(u_j) Rd_l(|X(u_j) - xo|)                (local, WITH_LOCAL, Sec. 4.2)
//   + ka Ia Ft(eta, N.V) mean(Ft) Rd_tot AO                   (WITH_AMBIENT)
//   then the optional Reinhard tone map, then Blinn-Phong specular (WITH_SPECULAR).
// Rd_g = Rd (1 - Wl), Rd_l = Rd Wl; without the hybrid Wl = 0. The same equations as
// renderer/techniques/dipole/reference.cpp, which integrates B directly instead.
// DEFERRED: a full-screen pass over the surface the `surface` pass stored (surface.frag)
// instead of the mesh, so each covered pixel sums the samples once rather than every
// rasterised fragment (llvmpipe shades whole 4x4 blocks of small triangles); the inputs
// are the same floats, so is the colour.
#include "techniques/dipole/shaders/dipole.glsl"
#include "techniques/shaders/surface_inputs.glsl"
#include "techniques/shaders/blinn_phong.glsl"
uniform vec3 u_light_direction;  // eye space, towards the light
uniform vec3 u_eye_object;       // camera position, object space
uniform vec3 u_background;
layout(location = 0) out vec4 o_colour;

#ifdef WITH_SUBSURFACE
uniform float u_scale;  // mm per mesh unit
uniform vec3 u_light_diffuse;
uniform sampler2D samples;     // rgba32f: xyz mm, w = 1 for a sample
uniform sampler2D irradiance;  // the mip pyramid; its top level is Phi / A^2
uniform int u_sample_count;
uniform int u_sample_side;
uniform int u_top_level;
uniform float u_texel_count;   // A^2
#endif
#if defined(WITH_SUBSURFACE) || defined(WITH_AMBIENT)
uniform float u_eta;
#endif
#ifdef WITH_LOCAL
uniform sampler2D light_flux;      // phi per plane area for Id = 1
uniform sampler2D light_position;  // xyz mm, w = 1 where the light sees the mesh
uniform sampler2D ring_pattern;    // per sample: plane offset (mm), weight (mm^2 / Rd)
uniform int u_ring_count;          // M = L C + 1
uniform mat4 u_light_view_projection;
uniform vec3 u_light_right;        // object space, unit
uniform vec3 u_light_up;
uniform float u_light_plane_mm;    // width of the light view in mm
#endif
#ifdef WITH_AMBIENT
uniform vec3 u_ambient_colour;  // ka Ia mean(Ft) Rd_tot
#endif
#ifdef TONE_MAP
uniform float u_tone_key;
uniform float u_tone_average_per_flux;  // Y(Id Rd_tot) / (pi total area)
#endif
#ifdef WITH_SPECULAR
uniform float u_specular;
uniform float u_shininess;
uniform vec3 u_light_specular;
#endif

void main() {
    Surface surface;
    if (!read_surface(surface)) {
        o_colour = vec4(u_background, 0.0);  // no surface: the clear colour
        return;
    }
    vec3 position_object = surface.position_object;
    vec3 normal_object = surface.normal_object;
    vec3 normal_eye = surface.normal_eye;
    float ambient_occlusion = surface.ambient_occlusion;
    vec3 n = normalize(normal_object);
    float n_dot_v = max(dot(n, normalize(u_eye_object - position_object)), 0.0);
    vec3 colour = vec3(0.0);
    float flux = 0.0;
#ifdef WITH_SUBSURFACE
    // Eq. 10 over the shared samples; Phi = the mean mass times the texel count.
    flux = texelFetch(irradiance, ivec2(0), u_top_level).r * u_texel_count;
    vec3 xo = position_object * u_scale;
    vec3 radiosity = vec3(0.0);
    if (flux > 0.0) {
        vec3 sum = vec3(0.0);
        for (int k = 0; k < u_sample_count; ++k) {
            vec4 s = texelFetch(samples, ivec2(k % u_sample_side, k / u_sample_side), 0);
            if (s.w == 0.0) continue;
            float r = distance(s.xyz, xo);
            sum += dipole_rd(r) * (1.0 - local_weight(r));
        }
        radiosity = flux / float(u_sample_count) * sum;
    }
#ifdef WITH_LOCAL
    // Sec. 4.2: the equal-mass ring pattern on the light plane around xo's projection.
    {
        vec4 clip = u_light_view_projection * vec4(position_object, 1.0);
        vec2 uv_o = clip.xy / clip.w * 0.5 + 0.5;
        vec3 sum = vec3(0.0);
        for (int j = 0; j < u_ring_count; ++j) {
            vec4 pattern = texelFetch(ring_pattern, ivec2(j, 0), 0);
            vec2 uv = uv_o + pattern.xy / u_light_plane_mm;
            if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0))))
                continue;
            vec4 x = texture(light_position, uv);
            if (x.w == 0.0) continue;
            float r = distance(x.xyz, xo);
            sum += pattern.z * texture(light_flux, uv).r * dipole_rd(r) * local_weight(r);
        }
        radiosity += sum;
    }
#endif
    colour += fresnel_transmittance(u_eta, n_dot_v) * u_light_diffuse * radiosity /
              3.14159265358979;
#endif
#ifdef WITH_AMBIENT
    colour += u_ambient_colour * fresnel_transmittance(u_eta, n_dot_v) * ambient_occlusion;
#endif
#ifdef TONE_MAP
    // Reinhard (the DirectX HDRLighting operator the paper cites): s = a L / L_avg.
    float average = u_tone_average_per_flux * flux;
    colour = average > 0.0 ? colour * (u_tone_key / average) : vec3(0.0);
    colour = max(colour, vec3(0.0));
    colour = colour / (1.0 + colour);
#endif
#ifdef WITH_SPECULAR
    vec3 ne = normalize(normal_eye);
    if (dot(ne, u_light_direction) > 0.0)
        colour += u_specular * u_light_specular *
                  blinn_phong_lobe(ne, u_light_direction, u_shininess);
#endif
    o_colour = vec4(colour, 1.0);
}
