#version 450 core
// Vertex stage of every technique's mesh passes (empirical, ward and contrast_reversed,
// dipole, htsm; thick_texture's sheets have their own): object-space position and
// normal (the dipole's scattering integral, the htsm's light view), eye-space normal and
// position (Ward's lobe needs the true view vector), and per-vertex AO from the
// `vertex_ao` stream at attribute 2 (WITH_AMBIENT_OCCLUSION, or the dipole's
// WITH_AMBIENT). Outputs a fragment stage does not read are removed at link time.
// INVARIANT_POSITION makes the depth of a vertex identical in every pass that draws it,
// which the empirical technique's depth peeling relies on (the others leave the
// compiler free to fuse the transform's multiply-adds).
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
#if defined(WITH_AMBIENT_OCCLUSION) || defined(WITH_AMBIENT)
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
#ifdef INVARIANT_POSITION
invariant gl_Position;
#endif

void main() {
    v_position_object = a_position;
    v_normal_object = a_normal;
    v_normal_eye = u_normal_matrix * a_normal;
#if defined(WITH_AMBIENT_OCCLUSION) || defined(WITH_AMBIENT)
    v_ambient_occlusion = a_ambient_occlusion;
#endif
    vec4 position_eye = u_model_view * vec4(a_position, 1.0);
    v_position_eye = position_eye.xyz;
    gl_Position = u_projection * position_eye;
}
