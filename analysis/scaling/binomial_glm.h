#pragma once
// A binomial generalized linear model fitted by iteratively reweighted least squares, as
// R's glm.fit does it (same starting values, link clamps and convergence rule), so that
// the paired-comparison and MLDS scales equal R's to the last digits R prints.
#include <Eigen/Dense>
#include <optional>

namespace lucent::analysis {

enum class BinomialLink {
    logit,   // Bradley-Terry
    probit,  // Thurstone Case V, MLDS
};

// One row per binomial observation: `successes` out of `trials` (rows with no trials
// carry no information and are left out, as R's zero weights are).
struct BinomialData {
    Eigen::MatrixXd x;  // design, no intercept unless a column of ones is given
    Eigen::VectorXd successes, trials;
    Eigen::VectorXd offset;  // empty: none
};

struct BinomialFit {
    Eigen::VectorXd coefficients;     // finite always; see `separation`
    Eigen::VectorXd standard_errors;  // sqrt(diag((X'WX)^-1)) at the estimate
    Eigen::MatrixXd covariance;
    Eigen::VectorXd fitted;  // probability per row (rows without trials: 0.5)
    double deviance = 0.0;
    double null_deviance = 0.0;  // of the offset alone (eta = offset; no intercept)
    // log-likelihood with the binomial coefficients (R's logLik and AIC for glm)
    double log_likelihood = 0.0;
    double aic = 0.0;      // -2 log-likelihood + 2 k
    int observations = 0;  // rows with trials
    int parameters = 0;    // k, the rank of X
    int df_residual = 0;   // observations - k
    int iterations = 0;
    bool converged = false;
    // Fitted probabilities at 0 or 1 (R: "fitted probabilities numerically 0 or 1
    // occurred") with coefficients still growing: the maximum lies at infinity.
    bool separation = false;
    bool rank_deficient = false;  // X'WX singular: some coefficient is not identified
};

// Throws std::invalid_argument on mismatched sizes. Convergence: relative change of the
// deviance below `epsilon` (R's glm.control; 1e-8 there, tighter here by default).
BinomialFit fit_binomial_glm(const BinomialData& data, BinomialLink link,
                             double epsilon = 1e-12, int max_iterations = 100);

// The link's inverse and its derivative, clamped as R's binomial() family clamps them.
double binomial_linkinv(BinomialLink link, double eta);
// log L of `successes` out of `trials` at probability p, with log choose(trials, s).
double binomial_log_likelihood(double successes, double trials, double p);

}  // namespace lucent::analysis
