// Blinn-Phong's specular lobe, shared by the empirical technique's shade.frag (thesis
// Eq. 3.9), the dipole's translucency and the htsm's shade (the CPU references' twin is
// renderer/cpu/blinn_phong.h, the same operations in double): max(N.H, 0)^shininess for
// a unit normal `n` and a unit direction `l` towards the light, both in eye space, with
// the viewer at infinity as OpenGL's fixed-function half vector (H = normalize(L +
// (0, 0, 1)), N.H = 0 where L points straight away from the viewer). Shininess 0 is a
// constant lobe (0^0 = 1); a non-positive N.H otherwise gives 0, where GLSL's pow is
// undefined. Callers apply their own N.L > 0 (and shadow) test.
float blinn_phong_lobe(vec3 n, vec3 l, float shininess) {
    vec3 h = l + vec3(0.0, 0.0, 1.0);
    float h_length2 = dot(h, h);
    float n_dot_h = h_length2 > 1e-30 ? max(dot(n, h * inversesqrt(h_length2)), 0.0) : 0.0;
    if (shininess == 0.0) return 1.0;
    return n_dot_h <= 0.0 ? 0.0 : pow(n_dot_h, shininess);
}
