// The surface a fragment shader lights: the mesh's interpolated varyings (mesh.vert), or,
// with DEFERRED, the same floats read back from what surface.frag stored (a full-screen
// pass then lights each covered pixel once). Shared by the dipole's translucency and the
// HTSM's shade. WITH_AMBIENT: the AO too; WITH_EYE_NORMAL: the eye-space normal.
#ifdef DEFERRED
uniform sampler2D surface_position;  // xyz object space; w = 1 where a surface is
uniform sampler2D surface_normal;    // xyz object space (interpolated); w = AO
#ifdef WITH_EYE_NORMAL
uniform sampler2D surface_normal_eye;
#endif
#else
in vec3 v_position_object;
in vec3 v_normal_object;
in vec3 v_normal_eye;
in vec3 v_position_eye;
#ifdef WITH_AMBIENT
in float v_ambient_occlusion;
#endif
#endif

struct Surface {
    vec3 position_object;
    vec3 normal_object;  // interpolated, not normalised
    vec3 normal_eye;     // interpolated, not normalised (WITH_EYE_NORMAL, or forward)
    float ambient_occlusion;
};

// False for a pixel no surface covers (deferred only).
bool read_surface(out Surface s) {
    s.normal_eye = vec3(0.0);
    s.ambient_occlusion = 0.0;
#ifdef DEFERRED
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 position = texelFetch(surface_position, pixel, 0);
    if (position.w == 0.0) return false;
    s.position_object = position.xyz;
    vec4 normal = texelFetch(surface_normal, pixel, 0);
    s.normal_object = normal.xyz;
    s.ambient_occlusion = normal.w;
#ifdef WITH_EYE_NORMAL
    s.normal_eye = texelFetch(surface_normal_eye, pixel, 0).xyz;
#endif
#else
    s.position_object = v_position_object;
    s.normal_object = v_normal_object;
    s.normal_eye = v_normal_eye;
#ifdef WITH_AMBIENT
    s.ambient_occlusion = v_ambient_occlusion;
#endif
#endif
    return true;
}
