#include "analysis/mixed/lmm.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <nlopt.hpp>
#include <numbers>

#include "analysis/data/long_table.h"  // InputError
#include "analysis/mixed/numeric_derivatives.h"

namespace lucent::analysis::mixed {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// lme4's isSingular() tolerance on the bounded (diagonal) theta.
constexpr double kSingularTolerance = 1e-4;

int lower_triangle_size(Eigen::Index q) { return int(q * (q + 1) / 2); }

// The model's fixed parts (Z, cross products) and the profiled deviance at a theta.
// Each evaluation leaves its solution (beta, u, r^2, log-determinants) in the members.
class ProfiledDeviance {
public:
    explicit ProfiledDeviance(const LmmSpec& spec) : spec_(spec), reml_(spec.reml) {
        n_ = spec.y.size();
        p_ = spec.fixed.x.cols();
        build_z();
        zt_ = z_.transpose();
        ztz_ = zt_ * z_;
        ztx_ = zt_ * spec.fixed.x;
        zty_ = zt_ * spec.y;
        xtx_ = spec.fixed.x.transpose() * spec.fixed.x;
        xty_ = spec.fixed.x.transpose() * spec.y;
        for (const auto& term : spec.random) {
            const auto q = term.z.cols();
            for (Eigen::Index c = 0; c < q; ++c)
                for (Eigen::Index r = c; r < q; ++r)
                    lower_bound_.push_back(r == c ? 0.0 : -HUGE_VAL);
        }
    }

    std::size_t theta_size() const { return lower_bound_.size(); }
    const std::vector<double>& lower_bounds() const { return lower_bound_; }
    Eigen::Index q() const { return z_.cols(); }

    // The profiled criterion (REML or ML) at theta.
    double operator()(const std::vector<double>& theta) {
        solve(theta);
        const double n = double(n_), p = double(p_);
        if (!reml_) return log_det_l2_ + n * (1.0 + std::log(kTwoPi * r2_ / n));
        return log_det_l2_ + log_det_rx2_ +
               (n - p) * (1.0 + std::log(kTwoPi * r2_ / (n - p)));
    }

    // lmerTest's deviance in (theta, sigma), not profiled over sigma.
    double deviance_at(const std::vector<double>& theta, double sigma) {
        solve(theta);
        const double s2 = sigma * sigma;
        double dev = log_det_l2_ + r2_ / s2 + double(n_) * std::log(kTwoPi * s2);
        if (reml_) dev += log_det_rx2_ - double(p_) * std::log(kTwoPi * s2);
        return dev;
    }

    // cov(beta) = sigma^2 (R_X'R_X)^-1 at theta, column-major.
    Eigen::MatrixXd beta_covariance(const std::vector<double>& theta, double sigma) {
        solve(theta);
        return sigma * sigma * rx_.solve(Eigen::MatrixXd::Identity(p_, p_));
    }

    double sigma_hat() const { return std::sqrt(r2_ / double(reml_ ? n_ - p_ : n_)); }
    const Eigen::VectorXd& beta() const { return beta_; }
    bool rx_positive() const { return rx_ok_; }

private:
    void build_z() {
        std::vector<Triplet> entries;
        Eigen::Index offset = 0;
        for (const auto& term : spec_.random) {
            const auto q = term.z.cols();
            for (Eigen::Index i = 0; i < n_; ++i)
                for (Eigen::Index c = 0; c < q; ++c)
                    entries.emplace_back(
                        int(i), int(offset + term.group.codes[std::size_t(i)] * q + c),
                        term.z(i, c));
            offset += Eigen::Index(term.group.levels.size()) * q;
        }
        z_.resize(n_, offset);
        z_.setFromTriplets(entries.begin(), entries.end());
    }

    // Lambda: per term, I_levels (x) T, T lower triangular from theta (column-major).
    SparseMatrix lambda(const std::vector<double>& theta) const {
        std::vector<Triplet> entries;
        Eigen::Index offset = 0;
        std::size_t base = 0;
        for (const auto& term : spec_.random) {
            const auto q = term.z.cols();
            const auto levels = Eigen::Index(term.group.levels.size());
            for (Eigen::Index level = 0; level < levels; ++level) {
                std::size_t k = base;
                for (Eigen::Index c = 0; c < q; ++c)
                    for (Eigen::Index r = c; r < q; ++r)
                        entries.emplace_back(int(offset + level * q + r),
                                             int(offset + level * q + c), theta[k++]);
            }
            offset += levels * q;
            base += std::size_t(lower_triangle_size(q));
        }
        SparseMatrix result(offset, offset);
        result.setFromTriplets(entries.begin(), entries.end());
        return result;
    }

    void solve(const std::vector<double>& theta) {
        const SparseMatrix lam = lambda(theta);
        const SparseMatrix lamt = lam.transpose();
        SparseMatrix a = lamt * ztz_ * lam;
        SparseMatrix identity(a.rows(), a.cols());
        identity.setIdentity();
        a += identity;
        a.makeCompressed();
        if (!analysed_ || a.nonZeros() != pattern_nonzeros_) {
            cholesky_.analyzePattern(a);
            pattern_nonzeros_ = a.nonZeros();
            analysed_ = true;
        }
        cholesky_.factorize(a);
        const auto& factor = cholesky_.matrixL().nestedExpression();
        log_det_l2_ = 2.0 * factor.diagonal().array().log().sum();

        const Eigen::MatrixXd lt_ztx = lamt * ztx_;
        const Eigen::VectorXd lt_zty = lamt * zty_;
        const Eigen::MatrixXd c_zx =
            cholesky_.matrixL().solve(cholesky_.permutationP() * lt_ztx);
        const Eigen::VectorXd c_u =
            cholesky_.matrixL().solve(cholesky_.permutationP() * lt_zty);
        const Eigen::MatrixXd rxtrx = xtx_ - c_zx.transpose() * c_zx;
        rx_.compute(rxtrx);
        rx_ok_ = rx_.info() == Eigen::Success;
        const Eigen::MatrixXd& rx_factor = rx_.matrixLLT();
        log_det_rx2_ = 2.0 * rx_factor.diagonal().array().log().sum();
        beta_ = rx_.solve(xty_ - c_zx.transpose() * c_u);
        const Eigen::VectorXd u =
            cholesky_.permutationPinv() *
            Eigen::VectorXd(cholesky_.matrixU().solve(c_u - c_zx * beta_));
        const Eigen::VectorXd residual = spec_.y - spec_.fixed.x * beta_ - z_ * (lam * u);
        r2_ = residual.squaredNorm() + u.squaredNorm();
    }

    const LmmSpec& spec_;
    bool reml_;
    Eigen::Index n_ = 0, p_ = 0;
    SparseMatrix z_, zt_, ztz_;
    Eigen::MatrixXd ztx_, xtx_;
    Eigen::VectorXd zty_, xty_;
    std::vector<double> lower_bound_;
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> cholesky_;
    bool analysed_ = false;
    Eigen::Index pattern_nonzeros_ = 0;
    Eigen::LLT<Eigen::MatrixXd> rx_;
    bool rx_ok_ = true;
    Eigen::VectorXd beta_;
    double r2_ = 0.0, log_det_l2_ = 0.0, log_det_rx2_ = 0.0;
};

void check_spec(const LmmSpec& spec) {
    const auto n = spec.y.size();
    if (spec.fixed.x.rows() != n)
        throw InputError("mixed model: the fixed-effects matrix has " +
                         std::to_string(spec.fixed.x.rows()) + " rows for " +
                         std::to_string(n) + " observations");
    if (!spec.y.allFinite())
        throw InputError("mixed model: the response has a missing or non-finite value");
    if (spec.random.empty())
        throw InputError(
            "mixed model: no random-effects term (fit a linear model instead)");
    for (const auto& term : spec.random) {
        if (term.z.rows() != n || Eigen::Index(term.group.codes.size()) != n)
            throw InputError("mixed model: the term for '" + term.group.name +
                             "' does not have one row per observation");
        if (Eigen::Index(term.group.levels.size()) >= n)
            throw InputError(
                "mixed model: '" + term.group.name + "' has " +
                std::to_string(term.group.levels.size()) + " levels for " +
                std::to_string(n) +
                " observations: its variance is confounded with the residual");
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(spec.fixed.x);
    if (qr.rank() < spec.fixed.x.cols())
        throw InputError(
            "mixed model: the fixed-effects columns are linearly dependent (rank " +
            std::to_string(qr.rank()) + " of " + std::to_string(spec.fixed.x.cols()) +
            ")");
    if (n <= spec.fixed.x.cols())
        throw InputError("mixed model: " + std::to_string(n) + " observations for " +
                         std::to_string(spec.fixed.x.cols()) + " fixed effects");
}

struct Optimum {
    std::vector<double> theta;
    double criterion = 0.0;
    int evaluations = 0;
    bool converged = true;
};

Optimum minimise(ProfiledDeviance& deviance, Convergence convergence) {
    const std::size_t k = deviance.theta_size();
    Optimum best;
    best.theta.assign(k, 0.0);
    // lme4's start: identity factors.
    const auto& lower = deviance.lower_bounds();
    for (std::size_t i = 0; i < k; ++i) best.theta[i] = lower[i] == 0.0 ? 1.0 : 0.0;
    nlopt::opt optimiser(nlopt::LN_BOBYQA, unsigned(k));
    optimiser.set_lower_bounds(lower);
    if (convergence == Convergence::lme4_default) {
        // lme4's nloptwrap defaults, with nloptr's own xtol_rel.
        optimiser.set_ftol_abs(1e-8);
        optimiser.set_xtol_abs(1e-8);
        optimiser.set_xtol_rel(1e-4);
    } else {
        optimiser.set_xtol_rel(1e-10);
        optimiser.set_ftol_rel(1e-15);
    }
    optimiser.set_maxeval(100000);
    struct Context {
        ProfiledDeviance* deviance;
        int evaluations = 0;
    } context{&deviance};
    optimiser.set_min_objective(
        [](const std::vector<double>& x, std::vector<double>&, void* data) {
            auto* c = static_cast<Context*>(data);
            ++c->evaluations;
            const double value = (*c->deviance)(x);
            return std::isfinite(value) ? value : HUGE_VAL;
        },
        &context);
    try {
        optimiser.optimize(best.theta, best.criterion);
    } catch (const nlopt::roundoff_limited&) {
        // the best point so far stands
    } catch (const std::exception&) {
        best.converged = false;
    }
    best.criterion = deviance(best.theta);
    best.evaluations = context.evaluations;
    return best;
}

std::vector<VarianceComponent> variance_components(const LmmSpec& spec,
                                                   const std::vector<double>& theta,
                                                   double sigma) {
    std::vector<VarianceComponent> components;
    std::size_t base = 0;
    for (const auto& term : spec.random) {
        const auto q = term.z.cols();
        Eigen::MatrixXd t = Eigen::MatrixXd::Zero(q, q);
        std::size_t k = base;
        for (Eigen::Index c = 0; c < q; ++c)
            for (Eigen::Index r = c; r < q; ++r) t(r, c) = theta[k++];
        base = k;
        const Eigen::MatrixXd covariance = sigma * sigma * t * t.transpose();
        for (Eigen::Index c = 0; c < q; ++c)
            components.push_back({term.group.name, term.names[std::size_t(c)], "",
                                  covariance(c, c), std::sqrt(covariance(c, c))});
        for (Eigen::Index c = 0; c < q; ++c)
            for (Eigen::Index r = c + 1; r < q; ++r) {
                const double scale = std::sqrt(covariance(r, r) * covariance(c, c));
                components.push_back({term.group.name, term.names[std::size_t(c)],
                                      term.names[std::size_t(r)], covariance(r, c),
                                      scale > 0.0 ? covariance(r, c) / scale : 0.0});
            }
    }
    components.push_back({"Residual", "", "", sigma * sigma, sigma});
    return components;
}

// Satterthwaite's tests (lmerTest): the covariance of the variance parameters and the
// Jacobian of cov(beta) over them, at the optimum.
class Satterthwaite {
public:
    Satterthwaite(ProfiledDeviance& deviance, const std::vector<double>& theta,
                  double sigma, std::vector<std::string>& notes) {
        Eigen::VectorXd varpar(Eigen::Index(theta.size() + 1));
        for (std::size_t i = 0; i < theta.size(); ++i) varpar[Eigen::Index(i)] = theta[i];
        varpar[varpar.size() - 1] = sigma;
        auto split = [](const Eigen::VectorXd& v) {
            return std::pair{std::vector<double>(v.data(), v.data() + v.size() - 1),
                             v[v.size() - 1]};
        };
        const Eigen::MatrixXd hessian = richardson_hessian(
            [&](const Eigen::VectorXd& v) {
                const auto [t, s] = split(v);
                return deviance.deviance_at(t, s);
            },
            varpar);
        p_ = deviance.beta().size();
        jacobian_ = richardson_jacobian(
            [&](const Eigen::VectorXd& v) {
                const auto [t, s] = split(v);
                const Eigen::MatrixXd c = deviance.beta_covariance(t, s);
                return Eigen::VectorXd(
                    Eigen::Map<const Eigen::VectorXd>(c.data(), c.size()));
            },
            varpar);
        // A = 2 H^-1; a Hessian that is not positive definite (a fit on the boundary)
        // is inverted on its positive eigenvalues only, and said so.
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(hessian);
        const auto& values = eigen.eigenvalues();
        constexpr double tolerance = 1e-8;  // lmerTest's
        Eigen::VectorXd inverse_values = Eigen::VectorXd::Zero(values.size());
        int dropped = 0;
        for (Eigen::Index i = 0; i < values.size(); ++i) {
            if (values[i] > tolerance)
                inverse_values[i] = 1.0 / values[i];
            else
                ++dropped;
        }
        if (dropped > 0)
            notes.push_back("the deviance's Hessian in the variance parameters has " +
                            std::to_string(dropped) +
                            " eigenvalue(s) at or below zero (a fit on the boundary): "
                            "Satterthwaite's degrees of freedom use the others");
        varpar_covariance_ = 2.0 * eigen.eigenvectors() * inverse_values.asDiagonal() *
                             eigen.eigenvectors().transpose();
        deviance.deviance_at(theta, sigma);  // leave the solution at the optimum
    }

    // The gradient of l' cov(beta) l over the variance parameters.
    Eigen::VectorXd gradient(const Eigen::VectorXd& l) const {
        Eigen::VectorXd g(jacobian_.cols());
        for (Eigen::Index j = 0; j < jacobian_.cols(); ++j) {
            const Eigen::Map<const Eigen::MatrixXd> dc(jacobian_.col(j).data(), p_, p_);
            g[j] = l.dot(dc * l);
        }
        return g;
    }

    std::optional<double> df(const Eigen::VectorXd& l, double variance) const {
        const Eigen::VectorXd g = gradient(l);
        const double denominator = g.dot(varpar_covariance_ * g);
        if (!(denominator > 0.0) || !std::isfinite(denominator)) return std::nullopt;
        const double df = 2.0 * variance * variance / denominator;
        return std::isfinite(df) ? std::optional(df) : std::nullopt;
    }

private:
    Eigen::Index p_ = 0;
    Eigen::MatrixXd jacobian_, varpar_covariance_;
};

std::optional<double> two_sided_t_p(double t, double df) {
    if (!std::isfinite(t) || !(df > 0.0)) return std::nullopt;
    boost::math::students_t distribution(df);
    return 2.0 * boost::math::cdf(boost::math::complement(distribution, std::abs(t)));
}

// lmerTest's contestMD: the F test of the rows of L, with the denominator degrees of
// freedom from the eigen-decomposition of L cov(beta) L'.
TermTest term_test(const std::string& term, const Eigen::MatrixXd& l,
                   const Eigen::VectorXd& beta, const Eigen::MatrixXd& covariance,
                   const Satterthwaite& satterthwaite) {
    TermTest test;
    test.term = term;
    const Eigen::MatrixXd vl = l * covariance * l.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(vl);
    // Descending, as R's eigen() orders them.
    const Eigen::VectorXd values = eigen.eigenvalues().reverse();
    const Eigen::MatrixXd vectors = eigen.eigenvectors().rowwise().reverse();
    const double tolerance = std::max(std::sqrt(2.220446049250313e-16) * values[0], 0.0);
    int q = 0;
    while (q < values.size() && values[q] > tolerance) ++q;
    test.num_df = q;
    if (q == 0) return test;
    const Eigen::MatrixXd ptl = vectors.leftCols(q).transpose() * l;
    double f = 0.0;
    std::vector<double> nu;
    for (int m = 0; m < q; ++m) {
        const double projected = ptl.row(m).dot(beta);
        f += projected * projected / values[m];
        const auto df = satterthwaite.df(ptl.row(m).transpose(), values[m]);
        if (!df) return test;
        nu.push_back(*df);
    }
    f /= q;
    double den_df = nu[0];
    if (q > 1) {
        if (std::any_of(nu.begin(), nu.end(), [](double v) { return v <= 2.0; })) {
            den_df = 2.0;
        } else {
            double e = 0.0;
            for (double v : nu) e += v / (v - 2.0);
            den_df = 2.0 * e / (e - q);
        }
    }
    test.f = f;
    test.den_df = den_df;
    if (std::isfinite(f) && den_df > 0.0) {
        boost::math::fisher_f distribution(q, den_df);
        test.p = boost::math::cdf(boost::math::complement(distribution, f));
    }
    return test;
}

std::vector<std::string> fixed_terms_in_order(const FixedDesign& design) {
    std::vector<std::string> terms;
    for (const auto& term : design.term_of_column)
        if (term != "(Intercept)" &&
            std::find(terms.begin(), terms.end(), term) == terms.end())
            terms.push_back(term);
    return terms;
}

}  // namespace

RandomTerm random_intercept(FactorColumn group) {
    RandomTerm term;
    term.z = Eigen::MatrixXd::Ones(Eigen::Index(group.codes.size()), 1);
    term.names = {"(Intercept)"};
    term.group = std::move(group);
    return term;
}

RandomTerm random_slopes(FactorColumn group, const FixedDesign& design,
                         const std::vector<std::string>& slopes) {
    RandomTerm term = random_intercept(std::move(group));
    for (const auto& name : slopes) {
        const auto found = std::find(design.names.begin(), design.names.end(), name);
        if (found == design.names.end())
            throw InputError("mixed model: no fixed-effects column '" + name +
                             "' for a random slope");
        term.z.conservativeResize(Eigen::NoChange, term.z.cols() + 1);
        term.z.col(term.z.cols() - 1) = design.x.col(found - design.names.begin());
        term.names.push_back(name);
    }
    return term;
}

LmmFit fit_lmm(const LmmSpec& spec) {
    check_spec(spec);
    ProfiledDeviance deviance(spec);
    const Optimum optimum = minimise(deviance, spec.convergence);

    LmmFit fit;
    fit.reml = spec.reml;
    fit.observations = int(spec.y.size());
    fit.criterion = optimum.criterion;
    fit.log_likelihood = -optimum.criterion / 2.0;
    fit.theta = optimum.theta;
    fit.sigma = deviance.sigma_hat();
    fit.evaluations = optimum.evaluations;
    fit.converged = optimum.converged;
    fit.parameters = int(spec.fixed.x.cols() + Eigen::Index(optimum.theta.size()) + 1);
    if (!fit.converged) fit.notes.push_back("the optimiser stopped before converging");
    const auto& lower = deviance.lower_bounds();
    for (std::size_t i = 0; i < fit.theta.size(); ++i)
        if (lower[i] == 0.0 && fit.theta[i] < kSingularTolerance) fit.singular = true;
    if (fit.singular)
        fit.notes.push_back(
            "boundary (singular) fit: a random-effect variance is zero or a correlation "
            "is +-1");

    const Eigen::VectorXd beta = deviance.beta();
    fit.fixed_covariance = deviance.beta_covariance(fit.theta, fit.sigma);
    fit.components = variance_components(spec, fit.theta, fit.sigma);
    const Satterthwaite satterthwaite(deviance, fit.theta, fit.sigma, fit.notes);
    const auto p = beta.size();
    for (Eigen::Index j = 0; j < p; ++j) {
        FixedEffect effect;
        effect.name = spec.fixed.names[std::size_t(j)];
        effect.estimate = beta[j];
        const double variance = fit.fixed_covariance(j, j);
        effect.standard_error = std::sqrt(variance);
        if (variance > 0.0) {
            effect.t = beta[j] / effect.standard_error;
            effect.df = satterthwaite.df(Eigen::VectorXd::Unit(p, j), variance);
            if (effect.df) effect.p = two_sided_t_p(*effect.t, *effect.df);
        }
        fit.fixed.push_back(effect);
    }
    for (const auto& term : fixed_terms_in_order(spec.fixed)) {
        const auto columns = columns_of_term(spec.fixed, term);
        Eigen::MatrixXd l = Eigen::MatrixXd::Zero(Eigen::Index(columns.size()), p);
        for (std::size_t r = 0; r < columns.size(); ++r)
            l(Eigen::Index(r), columns[r]) = 1.0;
        fit.anova.push_back(
            term_test(term, l, beta, fit.fixed_covariance, satterthwaite));
    }
    return fit;
}

LikelihoodRatioTest likelihood_ratio(LmmSpec reduced, LmmSpec full) {
    reduced.reml = false;
    full.reml = false;
    const LmmFit small = fit_lmm(reduced), large = fit_lmm(full);
    LikelihoodRatioTest test;
    test.log_likelihood_reduced = small.log_likelihood;
    test.log_likelihood_full = large.log_likelihood;
    test.df = large.parameters - small.parameters;
    test.chi_square = std::max(0.0, 2.0 * (large.log_likelihood - small.log_likelihood));
    if (test.df > 0) {
        boost::math::chi_squared distribution(test.df);
        test.p = boost::math::cdf(boost::math::complement(distribution, test.chi_square));
    }
    return test;
}

}  // namespace lucent::analysis::mixed
