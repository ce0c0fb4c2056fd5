#pragma once
// How many participants a planned study needs: the power of its tests by seeded
// simulation (with the Monte Carlo error of each estimate), the closed form where one
// exists, and the smallest number of participants that reaches a target power.
//
// The model is the simulator's (simulate.h) without the cut into a rating scale unless
// `likert` is set: a participant's response at level j is mean_j + b + e, b ~ N(0,
// participant_sd^2) shared by the participant's responses, e ~ N(0, residual_sd^2).
//   between: `participants` per level, each responding once at one level;
//   within:  `participants` in all, each responding once at every level.
// Closed forms (continuous responses only): for the between one-way ANOVA and, under the
// compound symmetry this model has, the within repeated-measures ANOVA, the noncentral F
// with lambda = n sum (mean_j - grand)^2 / sigma^2, sigma^2 = participant_sd^2 +
// residual_sd^2 between and residual_sd^2 within.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/long_table.h"  // InputError
#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

struct PowerSpec {
    Design design = Design::Within;
    int participants = 38;            // within: in all; between: per level
    std::vector<double> level_means;  // expected mean response per level
    double participant_sd = 0.0;
    double residual_sd = 1.0;
    double alpha = 0.10;
    int simulations = 2000;
    std::uint64_t seed = 1;
    bool likert = false;  // round and clamp responses to 1..7, as participants answer
};

struct PowerEstimate {
    double power = 0.0;
    double mc_error = 0.0;  // standard error of the estimate, sqrt(p (1 - p) / runs)
};
// The share of `runs` simulated studies that rejected, with its Monte Carlo error.
PowerEstimate power_estimate(long hits, int runs);

struct PairPower {
    std::string level_a, level_b;
    PowerEstimate estimate;
};

struct PowerResult {
    PowerSpec spec;
    // The one-way ANOVA of all responses (for a within design it ignores the pairing,
    // as the thesis's analysis did) and, within, the repeated-measures ANOVA with its
    // uncorrected p (sphericity holds in this model; the closed form's test) and with
    // the Greenhouse-Geisser p (what a cautious report uses; a little less power).
    PowerEstimate one_way_anova;
    std::optional<PowerEstimate> rm_anova, rm_anova_gg;
    // Pairwise tests: between, Tukey HSD; within, paired t-tests with Holm's correction.
    std::string pairwise_test;
    PowerEstimate any_pair;  // at least one pair significant
    std::vector<PairPower> pairs;
    std::optional<double> closed_form;  // of the primary ANOVA (see above)

    // The design's primary test: the RM ANOVA within, the one-way ANOVA between.
    const PowerEstimate& primary() const { return rm_anova ? *rm_anova : one_way_anova; }
};

// Throws InputError naming the field when the spec cannot describe a study.
void check_power_spec(const PowerSpec& spec);
PowerResult estimate_power(const PowerSpec& spec);
// The closed form of the primary ANOVA's power; empty for Likert responses.
std::optional<double> closed_form_power(const PowerSpec& spec);

struct SampleSize {
    std::optional<int> participants;  // empty: not reached by `max_participants`
    PowerResult at;                   // the estimate at that size (or at the maximum)
    int evaluations = 0;              // sizes simulated
};

// The smallest `participants` whose primary test reaches `target` power, by bisection
// on simulated power with common random numbers (the same seed at every size).
SampleSize smallest_sample(PowerSpec spec, double target, int max_participants);

}  // namespace lucent::analysis
