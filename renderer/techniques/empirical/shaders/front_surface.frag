#version 450 core
// Front layer (Sec. 3.1, step 1) with the surface the deferred `shade` pass lights: the
// interpolated normal (not normalised) and AO, stored exactly in rgba32f, so lighting
// them once per pixel gives the values shading each fragment would have.
in vec3 v_normal_eye;
#ifdef WITH_AMBIENT_OCCLUSION
in float v_ambient_occlusion;
#endif
layout(location = 0) out vec4 out_surface;

void main() {
#ifdef WITH_AMBIENT_OCCLUSION
    out_surface = vec4(v_normal_eye, v_ambient_occlusion);
#else
    out_surface = vec4(v_normal_eye, 0.0);
#endif
}
