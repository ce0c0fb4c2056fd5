#pragma once
// The physics of the dipole technique, GL-free and in millimetres (sigma in mm^-1, Rd in
// mm^-2, areas in mm^2): Jensen et al. 2001's materials and dipole diffusion profile
// (Chang et al. Table 1), exact Fresnel transmittance, the total diffuse reflectance in
// closed form, and the hybrid split of Chang et al. Sec. 4 with the weight's sign
// corrected. The GL shaders, the CPU reference and the tests all use these definitions.
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lucent::dipole {

inline constexpr double kPi = 3.14159265358979323846;

// One homogeneous material, per rgb channel.
struct Material {
    glm::dvec3 sigma_a{0.0};        // absorption coefficient, mm^-1, >= 0
    glm::dvec3 sigma_s_prime{0.0};  // reduced scattering coefficient, mm^-1, >= 0
    double eta = 1.3;               // relative index of refraction, [1, 2]
};

struct MaterialPreset {
    std::string name;
    Material material;
};
// Jensen, Marschner, Levoy and Hanrahan 2001, Fig. 5 (eta 1.3), in the order of that
// table: apple, chicken1, chicken2, cream, ketchup, marble, potato, skimmilk, skin1,
// skin2, spectralon, wholemilk.
const std::vector<MaterialPreset>& material_presets();
// nullptr when `name` is not a preset.
const Material* find_material_preset(std::string_view name);

// Fresnel transmittance from outside into the medium, 1 - Fr for unpolarised light at
// cos(theta) = mu (clamped to [0, 1]); exactly 1 for eta = 1 (no interface) and 0 at
// mu = 0 otherwise.
double fresnel_transmittance(double eta, double mu);
// 2 * integral_0^1 Ft(eta, mu) mu dmu: the fraction of uniform (cosine-weighted)
// irradiance that is transmitted (0.938868 at eta 1.3).
double mean_fresnel_transmittance(double eta);
// The internal diffuse Fresnel reflectance fit of JMLH01 (Groenhuis et al.), valid for
// eta >= 1.
double diffuse_fresnel_reflectance(double eta);

// The normal of Eq. 4's cosine N.L on the triangle (p0, p1, p2): its geometric (facet)
// normal, turned to the side of `shading` (the mean of its vertex normals), so a
// mesh wound either way faces out where its normals say. The flux into a flat facet
// is its area times E(N_facet), whatever normals its vertices carry: interpolated
// vertex normals smoothed across a sharp edge (an OBJ without normals, a shared rim
// vertex) tilt whole triangles, and the flux would depend on how the shape is
// tessellated (README.md, "Irradiance"). Falls back to `shading` (normalised, or +z)
// for a degenerate triangle.
glm::dvec3 facet_normal(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                        const glm::dvec3& shading);

// The dipole of one channel, with its constants precomputed. A channel with
// sigma_a + sigma_s' = 0 (nothing scatters) has Rd == 0.
class Dipole {
public:
    Dipole(double sigma_a, double sigma_s_prime, double eta);
    // Rd(r), mm^-2, for r >= 0 (Chang et al. Table 1 = JMLH01 Eq. 4). Finite at r = 0.
    double rd(double r) const;
    // integral_0^inf 2 pi r Rd(r) dr in closed form (JMLH01 Eq. 5).
    double total_reflectance() const;
    bool scatters() const { return scatters_; }
    double albedo() const { return albedo_; }        // alpha' = sigma_s' / sigma_t'
    double sigma_tr() const { return sigma_tr_; }    // sqrt(3 sigma_a sigma_t')
    double z_real() const { return z_real_; }        // zr = 1 / sigma_t', mm
    double z_virtual() const { return z_virtual_; }  // zv = zr (1 + 4A/3), mm
    // The importance 2 pi r Rd(r): the radial density whose crossing with c gives Rp.
    double radial_density(double r) const { return 2.0 * kPi * r * rd(r); }

private:
    bool scatters_ = false;
    double albedo_ = 0.0, sigma_tr_ = 0.0, z_real_ = 0.0, z_virtual_ = 0.0, a_ = 1.0;
};

// The three channels.
struct DipoleRgb {
    Dipole r, g, b;
    explicit DipoleRgb(const Material& m);
    const Dipole& operator[](int c) const { return c == 0 ? r : c == 1 ? g : b; }
    glm::dvec3 rd(double distance) const;
    glm::dvec3 total_reflectance() const;
};

// Rp (mm) of Chang et al. Sec. 4.1: the largest r where 2 pi r Rd(r) = c (c in mm^-1).
// nullopt when c is at or above the peak of 2 pi r Rd (no crossing, e.g. chicken at
// c = 0.1) or the channel does not scatter; that channel is then all global (Wl == 0).
std::optional<double> importance_crossing(const Dipole& dipole, double c);

// The local weight Wl(r) with the sign of the paper's Sec. 4.1 corrected:
//   1 - exp(K (r - Rp)) / 2  for r <= Rp,   exp(-K (r - Rp)) / 2  for r > Rp,
// C1 at Rp, Wl(Rp) = 1/2; Wg = 1 - Wl. No Rp: Wl == 0.
double local_weight(double r, std::optional<double> rp, double k);

// Per channel: what the local part of the hybrid integrates (Rd * Wl) and the global part
// (Rd * (1 - Wl)); they add up to Rd exactly.
struct HybridSplit {
    std::optional<double> rp[3];
    double k = 1.5;  // mm^-1
    glm::dvec3 local(const DipoleRgb& d, double r) const;
    glm::dvec3 global(const DipoleRgb& d, double r) const;
    bool any_local() const { return rp[0] || rp[1] || rp[2]; }
};
HybridSplit make_hybrid_split(const DipoleRgb& d, double c, double k);

// integral_0^inf 2 pi r Rd(r) Wl(r) dr per channel (mm^-2 * mm^2): the local mass Z_l.
glm::dvec3 local_mass(const DipoleRgb& d, const HybridSplit& split);

// The local part's pattern on the light plane (README.md): M = L C + 1 samples of equal
// mass under the widest channel's radial density 2 pi r Rd_l(r) / Z_l (the channel with
// the largest Rp): a centre sample and L rings of C at radii P^-1((1 + (l - 1/2) C) / M),
// ring l turned by frac(l * golden ratio). Sample k carries offset (mm, on the plane) and
// weight Z_l,w / (M Rd_l,w(rho_k)) (mm^2), so that
//   B_l,c ~= sum_k w_k phi(u_k) Rd_l,c(|X(u_k) - xo|).
// Without any Rp it is one sample of weight 0.
struct RingPattern {
    std::vector<glm::dvec2> offset;  // mm
    std::vector<double> radius;      // |offset|, mm
    std::vector<double> weight;      // mm^2 / (mm^-2 of Rd): see above
    int widest = -1;                 // channel, -1 without any Rp
};
RingPattern make_ring_pattern(const DipoleRgb& d, const HybridSplit& split, int rings,
                              int per_ring);

}  // namespace lucent::dipole
