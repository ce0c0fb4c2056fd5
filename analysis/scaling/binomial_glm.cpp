#include "analysis/scaling/binomial_glm.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lucent::analysis {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// R's probit linkinv clamps eta to +-qnorm(eps) (8.125...), so mu never reaches 0 or 1.
const double kProbitThreshold = -boost::math::quantile(boost::math::normal(), kEps);

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
double normal_pdf(double z) { return std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI); }

double mu_eta(BinomialLink link, double eta) {
    if (link == BinomialLink::logit) {
        // R's logit_mu_eta: 0 beyond |eta| > 30 would stall IRLS, so eps there.
        if (std::abs(eta) > 30.0) return kEps;
        const double e = std::exp(eta);
        return e / ((1.0 + e) * (1.0 + e));
    }
    return std::max(normal_pdf(eta), kEps);
}

// Unit deviance of y (a proportion) against mu, times the row's weight.
double deviance_term(double y, double mu, double weight) {
    auto ylogy = [](double a, double b) { return a > 0.0 ? a * std::log(a / b) : 0.0; };
    return 2.0 * weight * (ylogy(y, mu) + ylogy(1.0 - y, 1.0 - mu));
}

}  // namespace

double binomial_linkinv(BinomialLink link, double eta) {
    if (link == BinomialLink::logit) {
        if (eta < -30.0) return kEps;
        if (eta > 30.0) return 1.0 - kEps;
        return 1.0 / (1.0 + std::exp(-eta));
    }
    const double t = std::clamp(eta, -kProbitThreshold, kProbitThreshold);
    return normal_cdf(t);
}

double binomial_log_likelihood(double successes, double trials, double p) {
    const double failures = trials - successes;
    double value = std::lgamma(trials + 1.0) - std::lgamma(successes + 1.0) -
                   std::lgamma(failures + 1.0);
    if (successes > 0) value += successes * std::log(p);
    if (failures > 0) value += failures * std::log1p(-p);
    return value;
}

BinomialFit fit_binomial_glm(const BinomialData& data, BinomialLink link, double epsilon,
                             int max_iterations) {
    const Eigen::Index n_all = data.x.rows(), k = data.x.cols();
    if (data.successes.size() != n_all || data.trials.size() != n_all ||
        (data.offset.size() != 0 && data.offset.size() != n_all))
        throw std::invalid_argument(
            "fit_binomial_glm: rows of x, successes, trials and "
            "offset differ");
    // Rows without trials are dropped (R's zero prior weights).
    std::vector<Eigen::Index> kept;
    for (Eigen::Index i = 0; i < n_all; ++i)
        if (data.trials[i] > 0) kept.push_back(i);
    const Eigen::Index n = static_cast<Eigen::Index>(kept.size());
    Eigen::MatrixXd x(n, k);
    Eigen::VectorXd y(n), m(n), offset = Eigen::VectorXd::Zero(n);
    for (Eigen::Index r = 0; r < n; ++r) {
        x.row(r) = data.x.row(kept[r]);
        m[r] = data.trials[kept[r]];
        y[r] = data.successes[kept[r]] / m[r];
        if (data.offset.size()) offset[r] = data.offset[kept[r]];
    }

    BinomialFit fit;
    fit.observations = static_cast<int>(n);
    fit.coefficients = Eigen::VectorXd::Zero(k);
    auto deviance_of = [&](const Eigen::VectorXd& mu) {
        double d = 0.0;
        for (Eigen::Index r = 0; r < n; ++r) d += deviance_term(y[r], mu[r], m[r]);
        return d;
    };

    // R's binomial mustart: (m y + 0.5) / (m + 1), eta from it.
    Eigen::VectorXd mu(n), eta(n);
    for (Eigen::Index r = 0; r < n; ++r) {
        mu[r] = (m[r] * y[r] + 0.5) / (m[r] + 1.0);
        eta[r] = link == BinomialLink::logit
                     ? std::log(mu[r] / (1.0 - mu[r]))
                     : boost::math::quantile(boost::math::normal(), mu[r]);
    }
    double deviance = deviance_of(mu);
    Eigen::MatrixXd xtwx(k, k);
    Eigen::VectorXd beta = Eigen::VectorXd::Zero(k);
    bool have_beta = false;
    for (fit.iterations = 1; fit.iterations <= max_iterations; ++fit.iterations) {
        Eigen::VectorXd w(n), z(n);
        for (Eigen::Index r = 0; r < n; ++r) {
            const double d = mu_eta(link, eta[r]);
            const double variance = std::max(mu[r] * (1.0 - mu[r]), kEps * kEps);
            z[r] = eta[r] - offset[r] + (y[r] - mu[r]) / d;
            w[r] = m[r] * d * d / variance;
        }
        xtwx = x.transpose() * w.asDiagonal() * x;
        const Eigen::VectorXd xtwz = x.transpose() * (w.asDiagonal() * z);
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(xtwx);
        qr.setThreshold(1e-11);
        if (qr.rank() < k) fit.rank_deficient = true;
        Eigen::VectorXd next = qr.solve(xtwz);
        if (!next.allFinite()) break;
        Eigen::VectorXd next_eta = x * next + offset, next_mu(n);
        for (Eigen::Index r = 0; r < n; ++r)
            next_mu[r] = binomial_linkinv(link, next_eta[r]);
        double next_deviance = deviance_of(next_mu);
        // R halves the step while the deviance is not finite; with clamped links it
        // always is, but a step that overshoots is halved as well (robust near 0/1).
        for (int half = 0;
             have_beta && half < 30 && next_deviance > deviance * (1 + 1e-7) + 1e-9;
             ++half) {
            next = 0.5 * (next + beta);
            next_eta = x * next + offset;
            for (Eigen::Index r = 0; r < n; ++r)
                next_mu[r] = binomial_linkinv(link, next_eta[r]);
            next_deviance = deviance_of(next_mu);
        }
        const double change =
            std::abs(next_deviance - deviance) / (std::abs(next_deviance) + 0.1);
        beta = next;
        have_beta = true;
        eta = next_eta;
        mu = next_mu;
        deviance = next_deviance;
        if (change < epsilon) {
            fit.converged = true;
            break;
        }
    }
    fit.iterations = std::min(fit.iterations, max_iterations);
    fit.coefficients = beta;
    fit.fitted = Eigen::VectorXd::Constant(n_all, 0.5);
    for (Eigen::Index r = 0; r < n; ++r) fit.fitted[kept[r]] = mu[r];
    fit.deviance = deviance;

    // Covariance at the estimate: (X'WX)^-1 with the final weights.
    {
        Eigen::VectorXd w(n);
        for (Eigen::Index r = 0; r < n; ++r) {
            const double d = mu_eta(link, eta[r]);
            w[r] = m[r] * d * d / std::max(mu[r] * (1.0 - mu[r]), kEps * kEps);
        }
        xtwx = x.transpose() * w.asDiagonal() * x;
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(xtwx);
        qr.setThreshold(1e-11);
        fit.parameters = static_cast<int>(qr.rank());
        if (qr.rank() < k) {
            fit.rank_deficient = true;
            fit.covariance = Eigen::MatrixXd::Constant(k, k, NAN);
        } else {
            fit.covariance = qr.inverse();
        }
        fit.standard_errors = fit.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    }
    fit.df_residual = fit.observations - fit.parameters;

    double null_deviance = 0.0, log_likelihood = 0.0;
    bool at_bounds = false;
    for (Eigen::Index r = 0; r < n; ++r) {
        null_deviance += deviance_term(y[r], binomial_linkinv(link, offset[r]), m[r]);
        log_likelihood += binomial_log_likelihood(std::round(m[r] * y[r]), m[r], mu[r]);
        if (mu[r] < 10 * kEps || mu[r] > 1.0 - 10 * kEps) at_bounds = true;
    }
    fit.null_deviance = null_deviance;
    fit.log_likelihood = log_likelihood;
    fit.aic = -2.0 * log_likelihood + 2.0 * fit.parameters;
    // Coefficients running off: probabilities pinned at the link's clamp (or the
    // iteration limit reached with growing coefficients).
    fit.separation = at_bounds || (!fit.converged && beta.cwiseAbs().maxCoeff() > 15.0);
    return fit;
}

}  // namespace lucent::analysis
