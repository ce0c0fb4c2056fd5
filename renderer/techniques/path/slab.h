#pragma once
// `lucent truth slab`: the path technique's transport (walk.h) on an infinite
// plane-parallel slab in vacuum, lit from above, tallying the fractions of the incident
// power reflected at the first surface, reflected after entering, and transmitted
// (unscattered light included), each with its standard error. What the tests hold to
// closed forms and published values (MCML, adding-doubling).
#include <cstdint>
#include <string>

#include "renderer/techniques/path/transport.h"

namespace lucent::path {

struct SlabProblem {
    double albedo = 0.9;             // sigma_s / sigma_t
    double g = 0.0;                  // HG asymmetry, |g| < 1
    double optical_depth = 1.0;      // sigma_t d; inf: semi-infinite
    double eta = 1.0;                // slab index / outside index
    double incidence_cosine = 1.0;   // collimated at this mu
    bool diffuse_incidence = false;  // cosine-weighted instead
    std::uint64_t paths = 100'000;
    std::uint64_t seed = 1;
    WalkShortcuts shortcuts{};
    WalkLimits limits{};
};
// std::invalid_argument naming the field when a value is out of range.
void check_slab_problem(const SlabProblem& problem);

struct Tally {
    double mean = 0.0, standard_error = 0.0;
};
struct SlabResult {
    Tally specular_reflectance;  // reflected at the first surface, never entered
    Tally diffuse_reflectance;   // left through the lit surface after entering
    Tally total_transmittance;   // left through the far surface (unscattered included)
    Tally total_reflectance;     // specular + diffuse, per path
    WalkCounters counters;
    double seconds = 0.0;
};

// Runs the paths over all hardware threads, in fixed blocks with one random stream per
// path, so the result is the same for a seed whatever the thread count.
SlabResult run_slab(const SlabProblem& problem);

}  // namespace lucent::path
