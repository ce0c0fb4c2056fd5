#pragma once
// Linear mixed models as R's lme4::lmer fits them, with lmerTest's Satterthwaite tests.
//
// y = X beta + Z b + e, b ~ N(0, sigma^2 Lambda Lambda'), e ~ N(0, sigma^2 I). The fit
// minimises the profiled deviance (REML criterion or -2 log-likelihood) over the
// relative covariance factor's parameters theta, as Bates, Maechler, Bolker and Walker
// (2015, J. Stat. Softw. 67(1), section 3) derive it: a sparse Cholesky factor of
// Lambda'Z'Z Lambda + I (Eigen's SimplicialLLT, its ordering analysed once), then the
// fixed effects and sigma in closed form. theta is found by NLopt's BOBYQA within the
// bounds theta_ii >= 0, as lme4's default optimiser (nloptwrap) does.
//
// Where BOBYQA stops matters more than one might think: lme4's default stops when theta
// moves less than 1e-4 relative (nloptr's xtol_rel), where the deviance is flat to
// 1e-8, and its variance estimates are then up to 6e-5 relative from the optimum
// (Penicillin's sample variance; sleepstudy's Satterthwaite df 16.99973 there, 17.000002
// at the optimum). Lucent goes on to the optimum (theta to 1e-10 relative) unless asked
// to stop where lme4 does (Convergence::lme4_default), which retraces lme4's path with
// the same NLopt library but can part from it where rounding differs (Penicillin).
//
// Fixed-effect tests follow lmerTest: Satterthwaite's degrees of freedom from the
// Hessian of the deviance in (theta, sigma) and the Jacobian of cov(beta) there (both by
// Richardson-extrapolated central differences, as numDeriv computes them), t-tests per
// coefficient and Type III F tests per term. Nothing is ever NaN: what cannot be
// computed is empty with a sentence in `notes`.
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "analysis/mixed/model_frame.h"

namespace lucent::analysis::mixed {

// One random-effects term (columns | group): z holds the columns that vary over the
// group's levels (a column of ones for a random intercept).
struct RandomTerm {
    FactorColumn group;
    Eigen::MatrixXd z;               // n x q
    std::vector<std::string> names;  // q names, lme4's: "(Intercept)", "Days"
};

// (1 | group)
RandomTerm random_intercept(FactorColumn group);
// (1 + columns | group), correlated: the fixed design's columns named in `slopes`.
RandomTerm random_slopes(FactorColumn group, const FixedDesign& design,
                         const std::vector<std::string>& slopes);

enum class Convergence {
    optimum,  // theta to 1e-10 relative
    // lme4's nloptwrap settings: xtol_abs 1e-8, ftol_abs 1e-8, xtol_rel 1e-4
    lme4_default,
    // theta to 1e-7 relative: the deviance is then within ~1e-13 of its minimum (it is
    // flat there), all a likelihood-ratio test reads from a fit
    likelihood,
};

struct LmmSpec {
    Eigen::VectorXd y;
    FixedDesign fixed;
    std::vector<RandomTerm> random;
    bool reml = true;
    Convergence convergence = Convergence::optimum;
    // Where the search for theta starts (lme4's start, identity factors, when empty or of
    // the wrong length): a neighbouring fit's theta saves evaluations.
    std::vector<double> start_theta;
    // Satterthwaite's t and F tests (numerical derivatives: most of a small fit's cost);
    // a fit for its likelihood alone (likelihood_ratio's refits) goes without them.
    bool satterthwaite_tests = true;
};

// lme4's as.data.frame(VarCorr(fit)) rows: a variance (name_b empty) with its standard
// deviation, or a covariance with its correlation.
struct VarianceComponent {
    std::string group, name_a, name_b;
    double variance_or_covariance = 0.0;
    double sd_or_correlation = 0.0;
};

struct FixedEffect {
    std::string name;
    double estimate = 0.0, standard_error = 0.0;
    std::optional<double> df, t, p;  // Satterthwaite; empty with a note when undefined
};

// Type III test of one term (all its columns): lmerTest's anova(fit).
struct TermTest {
    std::string term;
    int num_df = 0;
    std::optional<double> den_df, f, p;
};

struct LmmFit {
    bool reml = true;
    int observations = 0;
    double criterion = 0.0;       // REML criterion, or deviance (-2 log L) for ML
    double log_likelihood = 0.0;  // -criterion / 2 (lme4's logLik)
    int parameters = 0;           // fixed effects + theta + sigma (logLik's df)
    std::vector<double> theta;
    double sigma = 0.0;  // residual standard deviation
    std::vector<FixedEffect> fixed;
    Eigen::MatrixXd fixed_covariance;
    std::vector<VarianceComponent> components;  // residual last
    std::vector<TermTest> anova;
    bool singular = false;  // lme4's isSingular (tolerance 1e-4)
    bool converged = true;
    int evaluations = 0;
    std::vector<std::string> notes;
};

// Throws InputError when the model cannot be set up (sizes, a rank-deficient X, fewer
// observations than parameters).
LmmFit fit_lmm(const LmmSpec& spec);

struct LikelihoodRatioTest {
    double chi_square = 0.0;
    int df = 0;
    double p = 1.0;
    double log_likelihood_reduced = 0.0, log_likelihood_full = 0.0;
};

// R's anova(reduced, full) for nested linear mixed models: both refitted by ML (as R
// refits REML fits before comparing them), the full model from its start_theta (e.g.
// its REML fit's), the reduced one from the full model's ML theta.
LikelihoodRatioTest likelihood_ratio(LmmSpec reduced, LmmSpec full);

}  // namespace lucent::analysis::mixed
