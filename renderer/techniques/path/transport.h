#pragma once
// The light transport both of the path technique's estimators run (the image tracer over
// a mesh, tracer.cpp, and the infinite slab of `lucent truth slab`, slab.cpp): one
// channel's medium, free-flight sampling, the Henyey-Greenstein phase function, the
// smooth dielectric interface, and the walk through a boundary that alternates between
// inside (the medium) and outside (vacuum). Double precision, GL-free, Embree-free (the
// boundary is a template parameter). README.md beside this file states every decision.
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <optional>

#include "renderer/core/density_volume.h"

namespace lucent::path {

inline constexpr double kPi = 3.14159265358979323846;

// PCG32 (O'Neill 2014, "PCG: a family of simple fast space-efficient statistically good
// algorithms"): 64-bit state, one of 2^63 streams. Eight lines, deterministic on every
// machine, unlike std::*_distribution; one stream per pixel and sample keeps a render
// the same for a seed whatever the thread count.
class Random {
public:
    Random(std::uint64_t seed, std::uint64_t stream);
    std::uint32_t next_u32();
    // Uniform in [0, 1): 32 random bits, so never 1 (log(1 - u) stays finite).
    double uniform() { return next_u32() * (1.0 / 4294967296.0); }

private:
    std::uint64_t state_ = 0, increment_ = 0;
};

// An orthonormal frame around unit n (Duff et al. 2017, branchless).
struct Frame {
    glm::dvec3 s, t, n;
    explicit Frame(glm::dvec3 unit_normal);
    glm::dvec3 to_world(glm::dvec3 local) const {
        return s * local.x + t * local.y + n * local.z;
    }
};

// Henyey-Greenstein phase function, normalised over the sphere: (1 - g^2) /
// (4 pi (1 + g^2 - 2 g mu)^(3/2)), mu the cosine between the incoming propagation
// direction and the outgoing one (mu = 1: straight on). |g| < 1.
double henyey_greenstein(double g, double mu);
// A direction drawn from it around the propagation direction `forward` (unit), by
// inverting its CDF in mu (isotropic for |g| < 1e-4, where that inversion loses digits).
glm::dvec3 sample_henyey_greenstein(double g, glm::dvec3 forward, double u1, double u2);

// Unpolarised Fresnel reflectance of a smooth dielectric for light arriving with cosine
// cos_i (in [0, 1]) from the side of index n_i into the side of index n_t, eta = n_t /
// n_i; 1 under total internal reflection, 0 for eta = 1.
double fresnel_dielectric(double cos_i, double eta);

// What happens to a ray that meets the smooth interface: reflected with probability
// F (fresnel_dielectric), refracted otherwise, so the path's weight is unchanged (the
// eta^2 radiance factor of a crossing is left out: every source and the sensor are
// outside, so a path crosses in as often as out and the factors cancel).
struct InterfaceEvent {
    glm::dvec3 direction;
    bool transmitted = false;
};
// `direction` unit, `outward` the unit surface normal pointing out of the medium,
// `medium_eta` the medium's index relative to the outside. `u` in [0, 1).
InterfaceEvent cross_interface(glm::dvec3 direction, glm::dvec3 outward,
                               double medium_eta, double u);

// A density field scaling one material's coefficients (the htsm density volumes): rho in
// [0, 1] over the mesh's box, trilinear. Null volume: rho = 1 everywhere.
struct DensityField {
    const DensityVolume* volume = nullptr;
    glm::dvec3 box_min{0.0}, box_extent{1.0};
    double density(glm::dvec3 position) const;
    double majorant() const { return volume ? volume->max : 1.0; }
    // Every lookup is the same number: callers may skip the lookups.
    bool constant() const { return !volume || volume->constant(); }
    double constant_value() const { return volume ? volume->max : 1.0; }
};

// One channel of a medium: coefficients per unit length (the boundary's units) at rho
// = 1.
struct ChannelMedium {
    double sigma_s = 0.0, sigma_a = 0.0;
    double g = 0.0;  // Henyey-Greenstein asymmetry
    DensityField density;
    double sigma_t() const { return sigma_s + sigma_a; }
    double albedo() const { return sigma_t() > 0.0 ? sigma_s / sigma_t() : 0.0; }
};

// Which of the walk's shortcuts may be taken (all of them, by default); `full` takes
// none, for the tests that hold each shortcut equal to the full walk.
struct WalkShortcuts {
    bool skip_fresnel_at_eta_1 = true;  // index-matched: the ray passes straight on
    bool no_collisions_without_scattering = true;  // sigma_s = 0: Beer-Lambert weight
    bool no_lookups_in_constant_density = true;    // constant rho: closed-form flights
    static WalkShortcuts none() { return {false, false, false}; }
};

// What one walk did, summed over walks for the summary line and `bench truth`.
struct WalkCounters {
    std::uint64_t scattering_events = 0;
    std::uint64_t boundary_queries = 0;  // rays traced to the boundary
    std::uint64_t null_collisions = 0;
    std::uint64_t density_lookups = 0;
    std::uint64_t interface_events = 0;
    std::uint64_t unfinished =
        0;                    // walks stopped at the event cap (reported, never silent)
    std::uint64_t leaks = 0;  // walks that found no boundary ahead inside the medium
    void add(const WalkCounters& other);
};

// Bounds on one walk. An albedo-1 walk in a semi-infinite medium returns with
// probability 1, but the number of events it takes has an infinite mean; the cap stops
// such a walk, counts it as unfinished and drops its weight (reported, so the loss is
// visible: P(unfinished) ~ 1/sqrt(pi cap)).
struct WalkLimits {
    std::uint64_t max_events = 100'000'000;
    // Below this weight, Russian roulette: survive with probability weight / floor at
    // weight floor (unbiased).
    double roulette_floor = 0.1;
};

// Samples the distance to the next real collision along a unit direction within
// [0, t_max): delta tracking over the density's majorant (heterogeneous), or the
// closed-form exponential (constant density). nullopt: none before t_max.
std::optional<double> sample_collision(const ChannelMedium& medium, glm::dvec3 origin,
                                       glm::dvec3 direction, double t_max, Random& random,
                                       const WalkShortcuts& shortcuts,
                                       WalkCounters& counters);
// Transmittance along [0, t) by ratio tracking (heterogeneous) or in closed form.
double transmittance(const ChannelMedium& medium, glm::dvec3 origin, glm::dvec3 direction,
                     double t, Random& random, const WalkShortcuts& shortcuts,
                     WalkCounters& counters);

// A boundary hit: the distance along the ray and the unit normal pointing out of the
// medium at that point.
struct BoundaryHit {
    double distance = 0.0;
    glm::dvec3 outward{0.0, 0.0, 1.0};
    std::uint32_t facet = 0;  // which flat piece of the boundary (a triangle, a plane)
};

}  // namespace lucent::path
