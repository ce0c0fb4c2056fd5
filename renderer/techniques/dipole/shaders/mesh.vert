#version 450 core
// Vertex stage of the dipole's mesh passes (light view and translucency): object-space
// position and normal for the scattering integral, eye-space normal for the specular
// term, and per-vertex AO for the ambient term.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
#ifdef WITH_AMBIENT
layout(location = 2) in float a_ambient_occlusion;
out float v_ambient_occlusion;
#endif
uniform mat4 u_model_view;
uniform mat4 u_projection;
uniform mat3 u_normal_matrix;
out vec3 v_position_object;
out vec3 v_normal_object;
out vec3 v_normal_eye;
out vec3 v_position_eye;

void main() {
    v_position_object = a_position;
    v_normal_object = a_normal;
    v_normal_eye = u_normal_matrix * a_normal;
#ifdef WITH_AMBIENT
    v_ambient_occlusion = a_ambient_occlusion;
#endif
    vec4 position_eye = u_model_view * vec4(a_position, 1.0);
    v_position_eye = position_eye.xyz;
    gl_Position = u_projection * position_eye;
}
