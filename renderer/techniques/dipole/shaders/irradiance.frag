#version 450 core
// Texel masses of the surfel atlas (Chang et al. Eqs. 4-7): E A = pi Ft(eta, N.L)
// max(N.L, 0) V A for Id = 1, with V from the light-view depth (the visibility the paper
// leaves out). Every texel has the same area, so the mass is proportional to E.
#include "techniques/dipole/shaders/dipole.glsl"
uniform sampler2D atlas_position;  // xyz mm, w = area mm^2 (0: no surface)
uniform sampler2D atlas_normal;
uniform sampler2D light_depth;
uniform mat4 u_light_view_projection;  // object space -> light clip space
uniform vec3 u_light_object;
uniform float u_eta;
uniform float u_scale;           // mm per mesh unit
uniform float u_normal_offset;   // mesh units: 1.5 light-map texels
uniform float u_depth_bias;      // window depth
out vec4 o_mass;

void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec4 position_area = texelFetch(atlas_position, texel, 0);
    vec3 n = texelFetch(atlas_normal, texel, 0).xyz;
    float mu = dot(n, u_light_object);
    float mass = 0.0;
    if (position_area.w > 0.0 && mu > 0.0) {
        // Visibility: the point, moved off the surface along its normal (normal-offset
        // shadow lookup), against the nearest depth seen from the light.
        vec3 p = position_area.xyz / u_scale + u_normal_offset * n;
        vec4 clip = u_light_view_projection * vec4(p, 1.0);
        vec3 ndc = clip.xyz / clip.w;
        vec2 uv = ndc.xy * 0.5 + 0.5;
        float depth = ndc.z * 0.5 + 0.5;
        float nearest = texture(light_depth, uv).r;
        if (depth <= nearest + u_depth_bias)
            mass = 3.14159265358979 * fresnel_transmittance(u_eta, mu) * mu * position_area.w;
    }
    o_mass = vec4(mass, 0.0, 0.0, 1.0);
}
