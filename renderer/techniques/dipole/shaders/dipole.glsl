// Shared by the dipole shaders (included after #version and the defines): the exact
// Fresnel transmittance and Jensen's dipole Rd, with the guards of
// renderer/techniques/dipole/scattering.cpp.

// 1 - Fr(eta, mu) for unpolarised light from outside; exactly 1 for eta = 1, and 1
// without WITH_FRESNEL (the planner's prune for eta = 1).
float fresnel_transmittance(float eta, float mu) {
#ifndef WITH_FRESNEL
    return 1.0;
#endif
    if (eta == 1.0) return 1.0;
    mu = clamp(mu, 0.0, 1.0);
    if (mu == 0.0) return 0.0;
    float cos_t = sqrt(max(0.0, 1.0 - (1.0 - mu * mu) / (eta * eta)));
    float rs = (mu - eta * cos_t) / (mu + eta * cos_t);
    float rp = (eta * mu - cos_t) / (eta * mu + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

// Per channel: alpha' / (4 pi) (0 for a channel that does not scatter), sigma_tr, zr,
// zv (zr = zv = 1 where nothing scatters, so no division by zero).
uniform vec3 u_rd_scale;
uniform vec3 u_sigma_tr;
uniform vec3 u_z_real;
uniform vec3 u_z_virtual;

vec3 dipole_pole(float r, vec3 z) {
    vec3 d = sqrt(r * r + z * z);
    return z * (1.0 + u_sigma_tr * d) * exp(-u_sigma_tr * d) / (d * d * d);
}

// Rd(r) in mm^-2 (Chang et al. Table 1).
vec3 dipole_rd(float r) {
    return u_rd_scale * (dipole_pole(r, u_z_real) + dipole_pole(r, u_z_virtual));
}

// The hybrid's local weight with the corrected sign (README.md), per channel; rp < 0
// marks a channel without Rp (all global).
uniform vec3 u_rp;
uniform float u_hybrid_k;
vec3 local_weight(float r) {
    vec3 w;
    for (int c = 0; c < 3; ++c) {
        float rp = u_rp[c];
        w[c] = rp < 0.0 ? 0.0
                        : (r <= rp ? 1.0 - 0.5 * exp(u_hybrid_k * (r - rp))
                                   : 0.5 * exp(-u_hybrid_k * (r - rp)));
    }
    return w;
}
