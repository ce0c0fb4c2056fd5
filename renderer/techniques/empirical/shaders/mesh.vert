#version 450 core
// Vertex stage of every empirical pass. `invariant` makes the depth of a vertex identical
// in the front-depth, peeling and shading passes, which the peel comparison relies on.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
#ifdef WITH_AMBIENT_OCCLUSION
layout(location = 2) in float a_ambient_occlusion;
out float v_ambient_occlusion;
#endif
uniform mat4 u_model_view;
uniform mat4 u_projection;
uniform mat3 u_normal_matrix;
out vec3 v_normal_eye;
invariant gl_Position;

void main() {
    v_normal_eye = u_normal_matrix * a_normal;
#ifdef WITH_AMBIENT_OCCLUSION
    v_ambient_occlusion = a_ambient_occlusion;
#endif
    gl_Position = u_projection * (u_model_view * vec4(a_position, 1.0));
}
