#version 450 core
// Ward's isotropic BRDF under the key light plus ambient (Domon et al. Eq. 14), or with
// REVERSED_DIFFUSE the contrast-reversed form (Eq. 15), in linear floating point:
//   ambient  = ka * Ia * Kd * ao
//   diffuse  = rho_d * Kd * Id * max(N.L, 0)                  (Eq. 14)
//   reversed = w * Id * chroma(Kd) * (1 - Y(Kd) * max(N.L, 0))  (Eq. 15 with Eq. 12 on
//              luminance, Li = Id; chroma = Kd / Y(Kd) keeps the albedo's hue)
//   specular = pi * f_s(l, v) * Is * max(N.L, 0)              (Eq. 13 with Ward's alpha^2)
// Terms that cannot change the image are compiled out by the planner. The guards match
// renderer/techniques/ward/ward_brdf.cpp.
in vec3 v_normal_eye;
in vec3 v_position_eye;
#ifdef WITH_AMBIENT_OCCLUSION
in float v_ambient_occlusion;
uniform float u_ambient;
uniform vec3 u_light_ambient;
#endif
#ifdef WITH_DIFFUSE
uniform float u_diffuse;  // rho_d, or the reversed-diffuse weight w
#ifdef REVERSED_DIFFUSE
uniform vec3 u_albedo_chroma;     // Kd / Y(Kd), white for a black albedo
uniform float u_albedo_luminance;  // Y(Kd), Rec. 709
#endif
#endif
#ifdef WITH_SPECULAR
uniform float u_specular_reflectance;
uniform float u_roughness;
uniform vec3 u_light_specular;
#endif
uniform vec3 u_albedo;
uniform vec3 u_light_diffuse;
uniform vec3 u_light_direction;  // unit, towards the light, eye space
layout(location = 0) out vec4 out_colour;

const float kPi = 3.14159265358979323846;
const float kMinRoughness = 1e-3;
const float kMinCosineProduct = 1e-4;

#ifdef WITH_SPECULAR
// Ward's isotropic lobe f_s (Eq. 13, alpha^2 normalisation); 0 below either horizon.
float ward_specular(vec3 n, vec3 l, vec3 v) {
    float cos_i = dot(n, l);
    float cos_o = dot(n, v);
    if (cos_i <= 0.0 || cos_o <= 0.0) return 0.0;
    vec3 sum = l + v;
    float length2 = dot(sum, sum);
    if (!(length2 > 0.0)) return 0.0;
    float cos_delta = dot(n, sum * inversesqrt(length2));
    if (cos_delta <= 0.0) return 0.0;
    float cos2 = cos_delta * cos_delta;
    float tan2 = max(1.0 - cos2, 0.0) / cos2;
    float a = max(u_roughness, kMinRoughness);
    float a2 = a * a;
    float cosine_product = max(cos_i * cos_o, kMinCosineProduct);
    return u_specular_reflectance * exp(-tan2 / a2) / (4.0 * kPi * a2 * sqrt(cosine_product));
}
#endif

void main() {
    // Unit normal and view vector; degenerate ones face the viewer.
    float n2 = dot(v_normal_eye, v_normal_eye);
    vec3 n = n2 > 1e-30 ? v_normal_eye * inversesqrt(n2) : vec3(0.0, 0.0, 1.0);
    float p2 = dot(v_position_eye, v_position_eye);
    vec3 v = p2 > 1e-30 ? -v_position_eye * inversesqrt(p2) : vec3(0.0, 0.0, 1.0);
    vec3 l = u_light_direction;
    float lit = max(dot(n, l), 0.0);
    vec3 colour = vec3(0.0);

#ifdef WITH_AMBIENT_OCCLUSION
    // Ambient: ka * Ia * Kd * ao
    colour += u_ambient * u_light_ambient * u_albedo * v_ambient_occlusion;
#endif
#ifdef WITH_DIFFUSE
#ifdef REVERSED_DIFFUSE
    // Reversed diffuse (Eq. 15): backlit luminance Li - I_directlit (Eq. 12), Li = Id
    colour += u_diffuse * u_light_diffuse * u_albedo_chroma * (1.0 - u_albedo_luminance * lit);
#else
    // Diffuse (Eq. 14): rho_d * Kd * Id * max(N.L, 0)
    colour += u_diffuse * u_albedo * u_light_diffuse * lit;
#endif
#endif
#ifdef WITH_SPECULAR
    // Specular: pi * f_s * Is * max(N.L, 0)
    colour += kPi * ward_specular(n, l, v) * u_light_specular * lit;
#endif
    out_colour = vec4(colour, 1.0);
}
