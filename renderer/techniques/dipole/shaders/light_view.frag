#version 450 core
// The mesh seen from the key light (orthographic, fitted to the bounding sphere): its
// depth gives the irradiance pass its visibility; WITH_LOCAL also stores, per texel of
// the light plane, the transmitted flux per unit plane area phi = pi Id Ft(eta, N.L)
// (for Id = 1; the cosine cancels against the projected area) and the position in mm,
// for the hybrid's local part (Chang et al. Sec. 4.2, after Dachsbacher and Stamminger).
in vec3 v_position_object;
in vec3 v_normal_object;
in vec3 v_normal_eye;
in vec3 v_position_eye;
#ifdef WITH_LOCAL
#include "techniques/dipole/shaders/dipole.glsl"
uniform vec3 u_light_object;
uniform float u_eta;
uniform float u_scale;  // mm per mesh unit
layout(location = 0) out vec4 o_flux;
layout(location = 1) out vec4 o_position;
#endif

void main() {
#ifdef WITH_LOCAL
    // The facet's normal (the plane of the triangle's positions), on the side of the
    // interpolated one, as the atlas and the CPU reference (scattering.h facet_normal).
    vec3 n = cross(dFdx(v_position_object), dFdy(v_position_object));
    float len = length(n);
    n = len > 0.0 ? n / len : normalize(v_normal_object);
    if (dot(n, v_normal_object) < 0.0) n = -n;
    float mu = dot(n, u_light_object);
    float phi = mu > 0.0 ? 3.14159265358979 * fresnel_transmittance(u_eta, mu) : 0.0;
    o_flux = vec4(phi, 0.0, 0.0, 1.0);
    o_position = vec4(v_position_object * u_scale, 1.0);
#endif
}
