#pragma once
// Cumulative link (mixed) models for ordinal ratings, equal to R's ordinal::clm and
// ordinal::clmm (Christensen 2019) with flexible thresholds:
//
//     P(Y <= j | x, b) = F(theta_j - x'beta - sum_g b_g),   b_g ~ N(0, tau_g^2),
//
// F the logistic or the normal distribution function, one random intercept per level of
// each grouping (none: clm; one; or two crossed groupings, e.g. participants and
// stimuli). Without random effects the log-likelihood is maximised by Newton-Raphson with
// its analytic gradient and Hessian. With them, the likelihood is clmm's default Laplace
// approximation,
//
//     log L ~= log p(y | u^) - u^'u^ / 2 - log det H(u^) / 2,   u = b / tau,
//
// with u^ the conditional modes (an inner Newton iteration; H is sparse: diagonal
// participant and stimulus blocks joined by their incidence, solved through the Schur
// complement on the smaller grouping), maximised over (thresholds, effects, tau) by
// BOBYQA and then polished by Newton steps on Richardson-extrapolated central
// differences, whose Hessian also gives the standard errors (clmm: nlminb, then a
// finite-difference Hessian). Cost per evaluation is O(observations + cells of the
// participant x stimulus incidence); the log-likelihood is summed with compensation (the
// differences would otherwise be rounding-noise limited), and the difference points are
// evaluated on two threads.
//
// Hard cases never give NaN or infinity: they are handled and said in `notes` (unused
// rating categories are dropped, zero or collinear fixed columns are dropped, a grouping
// with one level or confounded with the fixed effects is left out, a variance at zero is
// reported as a boundary (singular) fit, and an effect that runs to infinity under
// complete separation is flagged as not estimable).
#include <string>
#include <vector>

#include "analysis/mixed/model_frame.h"

namespace lucent::analysis::mixed {

enum class Link { Logit, Probit };

// How each evaluation of the Laplace likelihood finds the conditional modes u^.
enum class ClmmModes {
    // As clmm does by default (ordinal 2022.11, clmm.control(gradTol = 1e-4)): Newton
    // from u = 0 stopped once max|gradient| < 1e-4; with a single grouping the
    // log-determinant is that of the last Newton step's Hessian (its C routine NRalgv3).
    // The estimates then equal R's printed ones; they differ from the exact Laplace
    // approximation by about 1e-6 relative.
    AsR,
    // Modes converged to rounding level: the Laplace approximation itself.
    Exact,
};

struct ClmmSpec {
    FactorColumn response;  // ordered: levels[0] < levels[1] < ...
    FixedDesign fixed;      // no intercept column: the thresholds take its place
    std::vector<FactorColumn> random_intercepts;  // 0 (= clm), 1, or 2 crossed groupings
    Link link = Link::Logit;
    ClmmModes modes = ClmmModes::AsR;
    // False: the maximum only, without the extrapolated finite-difference Hessian of the
    // standard errors (a third of a fit's work); they then come from the Newton polish's
    // one-level Hessian at the optimiser's point (relative error up to ~1e-3). For the
    // reduced model of a likelihood-ratio test, which needs only its log-likelihood.
    bool precise_standard_errors = true;
};

// A threshold ("1|2") or an effect ("tempwarm").
struct ClmmEstimate {
    std::string name;
    double estimate = 0;
    double std_error = 0;  // 0 when not estimable
    // False when the parameter runs to infinity (complete separation): `estimate` is
    // where the optimiser stopped, its sign gives the direction; do not interpret it.
    bool estimable = true;
};

struct ClmmGrouping {
    std::string name;
    int levels = 0;
    double variance = 0, sd = 0;
    // False when the variance is not identifiable (one level, or the grouping is
    // confounded with the fixed effects): the model was fitted without it.
    bool identifiable = true;
    bool at_boundary = false;  // estimated as zero: "boundary (singular) fit"
};

struct ClmmFit {
    Link link = Link::Logit;
    std::vector<std::string> response_levels;  // the levels used, in order
    std::vector<ClmmEstimate> thresholds;      // "1|2", "2|3", ...
    std::vector<ClmmEstimate> coefficients;    // the fixed columns kept, in design order
    std::vector<std::string> dropped_columns;  // all-zero or collinear fixed columns
    std::vector<ClmmGrouping> groupings;       // one per spec.random_intercepts entry
    double log_likelihood = 0;                 // Laplace approximation with groupings
    int parameters = 0;  // R's df: thresholds + coefficients + variances
    int observations = 0;
    int iterations = 0;  // Newton steps (clm) or outer objective evaluations (clmm)
    bool converged = false;
    std::vector<std::string> notes;  // one sentence per hard case met; empty when none
};

ClmmFit fit_clmm(const ClmmSpec& spec);

// The log-likelihood fit_clmm maximises, at given parameters: thresholds, coefficients of
// the kept columns, one sd per identifiable grouping (all in spec order). For checking
// another program's estimates (R's printed log-likelihood is this at R's estimates).
// Throws InputError when the sizes do not match or the point is outside the model.
double clmm_log_likelihood_at(const ClmmSpec& spec, const std::vector<double>& thresholds,
                              const std::vector<double>& coefficients,
                              const std::vector<double>& sds);

// Likelihood-ratio test of one fixed term (all its columns, FixedDesign::term_of_column),
// as R's anova(reduced, full): the reduced model is `spec` refitted without the term.
struct ClmmLikelihoodRatioTest {
    std::string term;
    double log_likelihood_full = 0, log_likelihood_reduced = 0;
    int parameters_full = 0, parameters_reduced = 0;
    double chi_square = 0;           // 2 (full - reduced), never below 0
    int df = 0;                      // difference of parameter counts
    double p = 1;                    // upper chi-square tail; 1 when df is 0
    std::vector<std::string> notes;  // from both fits, and why a test is empty
};

ClmmLikelihoodRatioTest clmm_likelihood_ratio_test(const ClmmSpec& spec,
                                                   const ClmmFit& full,
                                                   const std::string& term);

// The reduced model's spec: `spec` without the term's columns, and without
// precise_standard_errors. Throws InputError when there is no such term.
ClmmSpec clmm_without_term(const ClmmSpec& spec, const std::string& term);

// The same test with the reduced model already fitted, `reduced` =
// fit_clmm(clmm_without_term(spec, term)) (so that both fits can run at the same time).
ClmmLikelihoodRatioTest clmm_likelihood_ratio_test(const ClmmFit& full,
                                                   const ClmmFit& reduced,
                                                   const std::string& term);

}  // namespace lucent::analysis::mixed
