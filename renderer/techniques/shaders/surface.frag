#version 450 core
// What a deferred lighting pass (techniques/deferred_surface.h: the dipole's translucency,
// the htsm's shade) lights, once per pixel: the nearest surface's
// interpolated object-space position (w = 1 marks a covered pixel) and normal (w = AO),
// and its eye-space normal (WITH_EYE_NORMAL), stored exactly in rgba32f, so shading them
// gives the floats shading each fragment would (surface_inputs.glsl reads them back).
in vec3 v_position_object;
in vec3 v_normal_object;
in vec3 v_normal_eye;
in vec3 v_position_eye;
#ifdef WITH_AMBIENT
in float v_ambient_occlusion;
#endif
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
#ifdef WITH_EYE_NORMAL
layout(location = 2) out vec4 o_normal_eye;
#endif

void main() {
    o_position = vec4(v_position_object, 1.0);
#ifdef WITH_AMBIENT
    o_normal = vec4(v_normal_object, v_ambient_occlusion);
#else
    o_normal = vec4(v_normal_object, 0.0);
#endif
#ifdef WITH_EYE_NORMAL
    o_normal_eye = vec4(v_normal_eye, 0.0);
#endif
}
