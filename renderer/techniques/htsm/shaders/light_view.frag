#version 450 core
// The HTSM reference images from the key light (Shopf Sec. 4.3, Fig. 4.2): per texel the
// first surface seen from the light, its Fresnel-transmitted irradiance
// E = Id max(N.L, 0) (1 - F_schlick(N.L)) and its 3-D texture coordinate
// t = (p - box_min) / box_extent, with alpha = coverage (the background is cleared to 0,
// so the box-filtered mips of t divided by their alpha are coverage-weighted means).
// Without WITH_TRANSPORT only the depth is written (the surface terms' shadow map).
in vec3 v_position_object;
in vec3 v_normal_object;
in vec3 v_normal_eye;
in vec3 v_position_eye;
#ifdef WITH_TRANSPORT
uniform vec3 u_to_light;  // object space, unit
uniform vec3 u_light_diffuse;
uniform float u_eta;
uniform vec3 u_box_min;
uniform vec3 u_box_extent;
layout(location = 0) out vec4 o_irradiance;
layout(location = 1) out vec4 o_texcoord;
#ifdef WITH_NORMAL
layout(location = 2) out vec4 o_normal;  // stored by the thesis, read by nothing
#endif

float schlick(float eta, float c) {
    if (eta == 1.0) return 0.0;
    float f0 = (eta - 1.0) / (eta + 1.0);
    f0 *= f0;
    float m = 1.0 - clamp(c, 0.0, 1.0);
    return f0 + (1.0 - f0) * m * m * m * m * m;
}
#endif

void main() {
#ifdef WITH_TRANSPORT
    vec3 n = normalize(v_normal_object);
    float c = dot(n, u_to_light);
    float e = c > 0.0 ? c * (1.0 - schlick(u_eta, c)) : 0.0;
    o_irradiance = vec4(u_light_diffuse * e, 1.0);
    o_texcoord = vec4((v_position_object - u_box_min) / u_box_extent, 1.0);
#ifdef WITH_NORMAL
    o_normal = vec4(n, 1.0);
#endif
#endif
}
