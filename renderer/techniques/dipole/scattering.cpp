#include "renderer/techniques/dipole/scattering.h"

#include <algorithm>
#include <cmath>

namespace lucent::dipole {

const std::vector<MaterialPreset>& material_presets() {
    // JMLH01 Fig. 5: sigma_s' and sigma_a in mm^-1 (r, g, b), all at eta = 1.3.
    static const std::vector<MaterialPreset> presets = {
        {"apple", {{0.0030, 0.0034, 0.046}, {2.29, 2.39, 1.97}, 1.3}},
        {"chicken1", {{0.015, 0.077, 0.19}, {0.15, 0.21, 0.38}, 1.3}},
        {"chicken2", {{0.018, 0.088, 0.20}, {0.19, 0.25, 0.32}, 1.3}},
        {"cream", {{0.0002, 0.0028, 0.0163}, {7.38, 5.47, 3.15}, 1.3}},
        {"ketchup", {{0.061, 0.97, 1.45}, {0.18, 0.07, 0.03}, 1.3}},
        {"marble", {{0.0021, 0.0041, 0.0071}, {2.19, 2.62, 3.00}, 1.3}},
        {"potato", {{0.0024, 0.0090, 0.12}, {0.68, 0.70, 0.55}, 1.3}},
        {"skimmilk", {{0.0014, 0.0025, 0.0142}, {0.70, 1.22, 1.90}, 1.3}},
        {"skin1", {{0.032, 0.17, 0.48}, {0.74, 0.88, 1.01}, 1.3}},
        {"skin2", {{0.013, 0.070, 0.145}, {1.09, 1.59, 1.79}, 1.3}},
        {"spectralon", {{0.0, 0.0, 0.0}, {11.6, 20.4, 14.9}, 1.3}},
        {"wholemilk", {{0.0011, 0.0024, 0.014}, {2.55, 3.21, 3.77}, 1.3}},
    };
    return presets;
}

const Material* find_material_preset(std::string_view name) {
    for (const auto& preset : material_presets())
        if (preset.name == name) return &preset.material;
    return nullptr;
}

double fresnel_transmittance(double eta, double mu) {
    if (eta == 1.0) return 1.0;
    mu = std::clamp(mu, 0.0, 1.0);
    if (mu == 0.0) return 0.0;
    // Snell from outside (index 1) into eta: never total internal reflection.
    const double cos_t = std::sqrt(std::max(0.0, 1.0 - (1.0 - mu * mu) / (eta * eta)));
    const double rs = (mu - eta * cos_t) / (mu + eta * cos_t);
    const double rp = (eta * mu - cos_t) / (eta * mu + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

double mean_fresnel_transmittance(double eta) {
    if (eta == 1.0) return 1.0;
    // Composite Simpson on 2 Ft(mu) mu over [0, 1]; smooth, so 4096 intervals give
    // ~1e-12.
    constexpr int n = 4096;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double mu = double(i) / n;
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * 2.0 * fresnel_transmittance(eta, mu) * mu;
    }
    return sum / (3.0 * n);
}

glm::dvec3 facet_normal(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                        const glm::dvec3& shading) {
    const glm::dvec3 cross = glm::cross(p1 - p0, p2 - p0);
    const double length = glm::length(cross);
    const double shading_length = glm::length(shading);
    if (!(length > 0.0) || !std::isfinite(length))
        return shading_length > 0.0 && std::isfinite(shading_length)
                   ? shading / shading_length
                   : glm::dvec3(0.0, 0.0, 1.0);
    const glm::dvec3 n = cross / length;
    return glm::dot(n, shading) < 0.0 ? -n : n;
}

double diffuse_fresnel_reflectance(double eta) {
    return -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
}

Dipole::Dipole(double sigma_a, double sigma_s_prime, double eta) {
    const double sigma_t = sigma_a + sigma_s_prime;
    scatters_ = sigma_t > 0.0 && sigma_s_prime > 0.0;
    if (!scatters_) return;
    const double fdr = diffuse_fresnel_reflectance(eta);
    a_ = (1.0 + fdr) / (1.0 - fdr);
    albedo_ = sigma_s_prime / sigma_t;
    sigma_tr_ = std::sqrt(3.0 * sigma_a * sigma_t);
    z_real_ = 1.0 / sigma_t;
    z_virtual_ = z_real_ * (1.0 + 4.0 * a_ / 3.0);
}

double Dipole::rd(double r) const {
    if (!scatters_) return 0.0;
    const auto pole = [&](double z) {
        // z (1 + sigma_tr d) exp(-sigma_tr d) / d^3 with d = sqrt(r^2 + z^2) >= z > 0
        const double d = std::sqrt(r * r + z * z);
        return z * (1.0 + sigma_tr_ * d) * std::exp(-sigma_tr_ * d) / (d * d * d);
    };
    return albedo_ / (4.0 * kPi) * (pole(z_real_) + pole(z_virtual_));
}

double Dipole::total_reflectance() const {
    if (!scatters_) return 0.0;
    const double s = std::sqrt(3.0 * (1.0 - albedo_));
    return 0.5 * albedo_ * (1.0 + std::exp(-4.0 / 3.0 * a_ * s)) * std::exp(-s);
}

DipoleRgb::DipoleRgb(const Material& m)
    : r(m.sigma_a.r, m.sigma_s_prime.r, m.eta),
      g(m.sigma_a.g, m.sigma_s_prime.g, m.eta),
      b(m.sigma_a.b, m.sigma_s_prime.b, m.eta) {}

glm::dvec3 DipoleRgb::rd(double distance) const {
    return {r.rd(distance), g.rd(distance), b.rd(distance)};
}

glm::dvec3 DipoleRgb::total_reflectance() const {
    return {r.total_reflectance(), g.total_reflectance(), b.total_reflectance()};
}

std::optional<double> importance_crossing(const Dipole& dipole, double c) {
    if (!dipole.scatters() || dipole.albedo() <= 0.0 || !(c > 0.0)) return std::nullopt;
    // 2 pi r Rd rises from 0 at r = 0 to one peak near zr and falls as r^-2 or faster:
    // scan a log grid from far to near for the first point above c, then bisect the
    // falling side for the largest crossing.
    const double zr = dipole.z_real();
    constexpr int n = 4000;
    const double lo = 1e-4 * zr, hi = 1e8 * zr;
    const auto r_at = [&](int i) { return lo * std::pow(hi / lo, double(i) / n); };
    for (int i = n - 1; i >= 0; --i) {
        if (dipole.radial_density(r_at(i)) <= c) continue;
        double inside = r_at(i), outside = r_at(i + 1);
        for (int step = 0; step < 200 && outside - inside > 1e-14 * outside; ++step) {
            const double mid = 0.5 * (inside + outside);
            (dipole.radial_density(mid) > c ? inside : outside) = mid;
        }
        return 0.5 * (inside + outside);
    }
    return std::nullopt;
}

double local_weight(double r, std::optional<double> rp, double k) {
    if (!rp) return 0.0;
    return r <= *rp ? 1.0 - 0.5 * std::exp(k * (r - *rp))
                    : 0.5 * std::exp(-k * (r - *rp));
}

glm::dvec3 HybridSplit::local(const DipoleRgb& d, double r) const {
    const glm::dvec3 rd = d.rd(r);
    return {rd.r * local_weight(r, rp[0], k), rd.g * local_weight(r, rp[1], k),
            rd.b * local_weight(r, rp[2], k)};
}

glm::dvec3 HybridSplit::global(const DipoleRgb& d, double r) const {
    return d.rd(r) - local(d, r);
}

HybridSplit make_hybrid_split(const DipoleRgb& d, double c, double k) {
    HybridSplit split;
    split.k = k;
    for (int ch = 0; ch < 3; ++ch) split.rp[ch] = importance_crossing(d[ch], c);
    return split;
}

namespace {

// 2 pi r Rd_l(r) of one channel tabulated on r = r_max t^2, with its cumulative
// (trapezoid); r_max = Rp + 40 / K, beyond which Wl < e^-40 / 2.
struct LocalProfile {
    std::vector<double> r, cumulative;
};
LocalProfile local_profile(const Dipole& d, double rp, double k) {
    constexpr int n = 40000;
    const double r_max = rp + 40.0 / k;
    LocalProfile p;
    p.r.resize(n + 1);
    p.cumulative.assign(n + 1, 0.0);
    double previous = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double t = double(i) / n;
        p.r[i] = r_max * t * t;
        const double density = d.radial_density(p.r[i]) * local_weight(p.r[i], rp, k);
        if (i > 0)
            p.cumulative[i] =
                p.cumulative[i - 1] + 0.5 * (density + previous) * (p.r[i] - p.r[i - 1]);
        previous = density;
    }
    return p;
}

}  // namespace

glm::dvec3 local_mass(const DipoleRgb& d, const HybridSplit& split) {
    glm::dvec3 z(0.0);
    for (int c = 0; c < 3; ++c)
        if (split.rp[c])
            z[c] = local_profile(d[c], *split.rp[c], split.k).cumulative.back();
    return z;
}

RingPattern make_ring_pattern(const DipoleRgb& d, const HybridSplit& split, int rings,
                              int per_ring) {
    RingPattern pattern;
    for (int c = 0; c < 3; ++c)
        if (split.rp[c] &&
            (pattern.widest < 0 || *split.rp[c] > *split.rp[pattern.widest]))
            pattern.widest = c;
    if (pattern.widest < 0 || rings < 1 || per_ring < 1) {
        pattern.offset = {glm::dvec2(0.0)};
        pattern.radius = {0.0};
        pattern.weight = {0.0};
        pattern.widest = -1;
        return pattern;
    }
    const Dipole& w = d[pattern.widest];
    const double rp = *split.rp[pattern.widest];
    const LocalProfile profile = local_profile(w, rp, split.k);
    const double z = profile.cumulative.back();
    const int m = rings * per_ring + 1;
    const auto inverse = [&](double share) {  // P^-1 by bisection + linear interpolation
        const double target = share * z;
        const auto it = std::lower_bound(profile.cumulative.begin(),
                                         profile.cumulative.end(), target);
        const std::size_t i = std::clamp<std::size_t>(
            std::size_t(it - profile.cumulative.begin()), 1, profile.r.size() - 1);
        const double c0 = profile.cumulative[i - 1], c1 = profile.cumulative[i];
        const double f = c1 > c0 ? (target - c0) / (c1 - c0) : 0.0;
        return profile.r[i - 1] + f * (profile.r[i] - profile.r[i - 1]);
    };
    const auto weight_at = [&](double rho) {
        const double rd_local = w.rd(rho) * local_weight(rho, rp, split.k);
        return rd_local > 0.0 ? z / (double(m) * rd_local) : 0.0;
    };
    pattern.offset.push_back(glm::dvec2(0.0));
    pattern.radius.push_back(0.0);
    pattern.weight.push_back(weight_at(0.0));
    constexpr double golden = 0.6180339887498949;
    for (int l = 1; l <= rings; ++l) {
        const double rho = inverse((1.0 + (double(l) - 0.5) * per_ring) / double(m));
        const double turn = std::fmod(double(l) * golden, 1.0);
        for (int j = 0; j < per_ring; ++j) {
            const double angle = 2.0 * kPi * (double(j) + turn) / per_ring;
            pattern.offset.push_back(rho * glm::dvec2(std::cos(angle), std::sin(angle)));
            pattern.radius.push_back(rho);
            pattern.weight.push_back(weight_at(rho));
        }
    }
    return pattern;
}

}  // namespace lucent::dipole
