#version 450 core
// Vertex stage of the sheet layers: eye-space position, normal and tangent (with its
// handedness) and the level-0 texel position uv * density / tile (the repeat sampler's
// coordinate).
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
#ifndef THIN
layout(location = 4) in vec4 a_tangent;
out vec4 v_tangent_eye;
#endif
layout(location = 3) in vec2 a_uv;
uniform mat4 u_model_view;  // view * the sheet's rotation (rigid)
uniform mat4 u_projection;
uniform vec3 u_uv_scale;    // xy: density / tile size
out vec3 v_position_eye;
out vec3 v_normal_eye;
out vec2 v_st;

void main() {
    mat3 rotation = mat3(u_model_view);
    v_normal_eye = rotation * a_normal;
#ifndef THIN
    v_tangent_eye = vec4(rotation * a_tangent.xyz, a_tangent.w);
#endif
    v_st = a_uv * u_uv_scale.xy;
    vec4 position_eye = u_model_view * vec4(a_position, 1.0);
    v_position_eye = position_eye.xyz;
    gl_Position = u_projection * position_eye;
}
