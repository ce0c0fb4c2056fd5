#include "renderer/techniques/path/transport.h"

#include <algorithm>
#include <cmath>

namespace lucent::path {

Random::Random(std::uint64_t seed, std::uint64_t stream) {
    increment_ = (stream << 1u) | 1u;
    next_u32();
    state_ += seed;
    next_u32();
}

std::uint32_t Random::next_u32() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rotation = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rotation) | (xorshifted << ((~rotation + 1u) & 31u));
}

Frame::Frame(glm::dvec3 unit_normal) : n(unit_normal) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    s = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
    t = {b, sign + n.y * n.y * a, -n.y};
}

double henyey_greenstein(double g, double mu) {
    const double denominator = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) / (4.0 * kPi * denominator * std::sqrt(denominator));
}

glm::dvec3 sample_henyey_greenstein(double g, glm::dvec3 forward, double u1, double u2) {
    double mu;
    if (std::abs(g) < 1e-4) {
        mu = 1.0 - 2.0 * u1;
    } else {
        const double ratio = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        mu = (1.0 + g * g - ratio * ratio) / (2.0 * g);
    }
    mu = std::clamp(mu, -1.0, 1.0);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double phi = 2.0 * kPi * u2;
    const Frame frame(forward);
    return glm::normalize(
        frame.to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu}));
}

double fresnel_dielectric(double cos_i, double eta) {
    cos_i = std::clamp(cos_i, 0.0, 1.0);
    if (eta == 1.0) return 0.0;
    const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) return 1.0;
    const double cos_t = std::sqrt(1.0 - sin2_t);
    const double parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const double perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (parallel * parallel + perpendicular * perpendicular);
}

InterfaceEvent cross_interface(glm::dvec3 direction, glm::dvec3 outward,
                               double medium_eta, double u) {
    const double d_dot_n = glm::dot(direction, outward);
    const bool entering = d_dot_n < 0.0;
    // The normal on the side the light comes from, and the index ratio n_t / n_i.
    const glm::dvec3 facing = entering ? outward : -outward;
    const double eta = entering ? medium_eta : 1.0 / medium_eta;
    const double cos_i = std::min(1.0, std::abs(d_dot_n));
    const double reflectance = fresnel_dielectric(cos_i, eta);
    if (u < reflectance) return {glm::normalize(direction + 2.0 * cos_i * facing), false};
    const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    const double cos_t = std::sqrt(std::max(0.0, 1.0 - sin2_t));
    return {glm::normalize(direction / eta + (cos_i / eta - cos_t) * facing), true};
}

double DensityField::density(glm::dvec3 position) const {
    if (!volume) return 1.0;
    return volume->sample((position - box_min) / box_extent);
}

void WalkCounters::add(const WalkCounters& other) {
    scattering_events += other.scattering_events;
    boundary_queries += other.boundary_queries;
    null_collisions += other.null_collisions;
    density_lookups += other.density_lookups;
    interface_events += other.interface_events;
    unfinished += other.unfinished;
    leaks += other.leaks;
}

namespace {

// A flight length for extinction `sigma` (> 0).
double exponential_flight(double sigma, Random& random) {
    return -std::log1p(-random.uniform()) / sigma;
}

}  // namespace

std::optional<double> sample_collision(const ChannelMedium& medium, glm::dvec3 origin,
                                       glm::dvec3 direction, double t_max, Random& random,
                                       const WalkShortcuts& shortcuts,
                                       WalkCounters& counters) {
    const double sigma_t = medium.sigma_t();
    if (!(sigma_t > 0.0)) return std::nullopt;
    if (medium.density.constant() && shortcuts.no_lookups_in_constant_density) {
        const double sigma = sigma_t * medium.density.constant_value();
        if (!(sigma > 0.0)) return std::nullopt;
        const double t = exponential_flight(sigma, random);
        return t < t_max ? std::optional<double>(t) : std::nullopt;
    }
    // Delta tracking (Woodcock): tentative collisions at the majorant's rate, each real
    // with probability rho(x) / rho_max. Analog, so the weight stays bounded.
    const double majorant = sigma_t * medium.density.majorant();
    if (!(majorant > 0.0)) return std::nullopt;
    double t = 0.0;
    for (;;) {
        t += exponential_flight(majorant, random);
        if (t >= t_max) return std::nullopt;
        ++counters.density_lookups;
        const double rho = medium.density.density(origin + t * direction);
        if (random.uniform() * medium.density.majorant() < rho) return t;
        ++counters.null_collisions;
    }
}

double transmittance(const ChannelMedium& medium, glm::dvec3 origin, glm::dvec3 direction,
                     double t, Random& random, const WalkShortcuts& shortcuts,
                     WalkCounters& counters) {
    const double sigma_t = medium.sigma_t();
    if (!(sigma_t > 0.0) || !(t > 0.0)) return 1.0;
    if (medium.density.constant() && shortcuts.no_lookups_in_constant_density)
        return std::exp(-sigma_t * medium.density.constant_value() * t);
    // Ratio tracking (Cramer 1978; Novak et al. 2014): the product of the null
    // probabilities at the majorant's tentative collisions, unbiased.
    const double majorant_density = medium.density.majorant();
    const double majorant = sigma_t * majorant_density;
    if (!(majorant > 0.0)) return 1.0;
    double estimate = 1.0, s = 0.0;
    for (;;) {
        s += exponential_flight(majorant, random);
        if (s >= t) return estimate;
        ++counters.density_lookups;
        estimate *=
            1.0 - medium.density.density(origin + s * direction) / majorant_density;
        if (estimate <= 0.0) return 0.0;
    }
}

}  // namespace lucent::path
