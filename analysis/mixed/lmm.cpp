#include "analysis/mixed/lmm.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <map>
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

// Two crossed random intercepts (participants and stimuli): Lambda'Z'Z Lambda + I =
// [[D1, C], [C', D2]] with D1 and D2 diagonal (one level per observation within a
// grouping). Eliminating the grouping with more levels leaves a dense Schur complement on
// the other, S = D2 - C' D1^-1 C, formed by one symmetric rank update and factored by a
// dense LLT: the work a sparse Cholesky does for this pattern, at dense-kernel speed. The
// factor L = [[D1^1/2, 0], [C' D1^-1/2, L_S]] is used through its two triangular solves.
class TwoInterceptFactor {
public:
    // `ztz` in Z's column order: the first term's levels, then the second's.
    TwoInterceptFactor(const SparseMatrix& ztz, Eigen::Index first_levels) {
        const Eigen::Index second_levels = ztz.cols() - first_levels;
        big_first_ = first_levels >= second_levels;
        big_begin_ = big_first_ ? 0 : first_levels;
        big_ = big_first_ ? first_levels : second_levels;
        small_begin_ = big_first_ ? first_levels : 0;
        small_ = ztz.cols() - big_;
        big_counts_.setZero(big_);
        small_counts_.setZero(small_);
        cross_.setZero(big_, small_);
        for (Eigen::Index c = 0; c < ztz.outerSize(); ++c)
            for (SparseMatrix::InnerIterator it(ztz, c); it; ++it) {
                const Eigen::Index r = it.row();
                if (r == c && in_big(r))
                    big_counts_[r - big_begin_] = it.value();
                else if (r == c)
                    small_counts_[r - small_begin_] = it.value();
                else if (in_big(r) && !in_big(c))
                    cross_(r - big_begin_, c - small_begin_) = it.value();
            }
        group_identical_rows();
    }

    // Which of theta's two entries scales which block.
    void factorize(double theta_first, double theta_second) {
        const double big_theta = big_first_ ? theta_first : theta_second;
        const double small_theta = big_first_ ? theta_second : theta_first;
        cross_scale_ = big_theta * small_theta;
        big_diagonal_ = (big_theta * big_theta) * big_counts_.array() + 1.0;
        big_root_ = big_diagonal_.sqrt();
        // The buffers are kept between evaluations: at 10^5 ratings a fresh 270 kB
        // matrix per evaluation cost more in page faults than the arithmetic.
        schur_matrix_.setZero(small_, small_);
        schur_matrix_.diagonal() =
            ((small_theta * small_theta) * small_counts_.array() + 1.0).matrix();
        // C'D1^-1 C summed over distinct rows of C, each weighted by how often it occurs.
        for (Eigen::Index g = 0; g < distinct_rows_.rows(); ++g)
            weighted_.row(g) =
                std::sqrt(group_size_[g] / big_diagonal_[group_member_[std::size_t(g)]]) *
                distinct_rows_.row(g);
        schur_matrix_.selfadjointView<Eigen::Lower>().rankUpdate(
            weighted_.transpose(), -cross_scale_ * cross_scale_);
        schur_.compute(schur_matrix_);
        log_det_ = big_diagonal_.log().sum() +
                   2.0 * schur_.matrixLLT().diagonal().array().log().sum();
    }

    double log_det() const { return log_det_; }
    bool ok() const { return schur_.info() == Eigen::Success; }

    // L^-1 b for b in Z's column order; the result is in the factor's own order (the
    // profiled deviance only uses its inner products and `backward`).
    Eigen::MatrixXd forward(const Eigen::MatrixXd& b) const {
        const auto b1 = b.middleRows(big_begin_, big_).array();
        Eigen::MatrixXd x(b.rows(), b.cols());
        x.topRows(big_) = (b1.colwise() / big_root_).matrix();
        x.bottomRows(small_) = b.middleRows(small_begin_, small_);
        x.bottomRows(small_).noalias() -=
            cross_scale_ * cross_.transpose() * (b1.colwise() / big_diagonal_).matrix();
        schur_.matrixL().solveInPlace(x.bottomRows(small_));
        return x;
    }

    // L'^-1 v, returned in Z's column order.
    Eigen::VectorXd backward(const Eigen::VectorXd& v) const {
        const Eigen::VectorXd y2 = schur_.matrixU().solve(v.tail(small_));
        Eigen::VectorXd y(v.size());
        y.segment(big_begin_, big_) =
            (v.head(big_).array() / big_root_ -
             cross_scale_ * (cross_ * y2).array() / big_diagonal_)
                .matrix();
        y.segment(small_begin_, small_) = y2;
        return y;
    }

private:
    // Participants with the same counts per stimulus (every one of them in a complete
    // crossed design) contribute the same term to the Schur complement: one rank update
    // per distinct row instead of per participant.
    void group_identical_rows() {
        std::map<std::vector<double>, Eigen::Index> group_of_row;
        std::vector<Eigen::Index> members;
        std::vector<double> sizes;
        for (Eigen::Index r = 0; r < big_; ++r) {
            std::vector<double> row(std::size_t(small_), 0.0);
            for (Eigen::Index c = 0; c < small_; ++c) row[std::size_t(c)] = cross_(r, c);
            const auto [at, inserted] =
                group_of_row.emplace(std::move(row), Eigen::Index(members.size()));
            if (inserted) {
                members.push_back(r);
                sizes.push_back(0.0);
            }
            sizes[std::size_t(at->second)] += 1.0;
        }
        distinct_rows_.resize(Eigen::Index(members.size()), small_);
        for (std::size_t g = 0; g < members.size(); ++g)
            distinct_rows_.row(Eigen::Index(g)) = cross_.row(members[g]);
        group_member_ = std::move(members);
        group_size_ =
            Eigen::Map<const Eigen::VectorXd>(sizes.data(), Eigen::Index(sizes.size()));
        weighted_.resize(distinct_rows_.rows(), small_);
    }

    bool in_big(Eigen::Index index) const {
        return index >= big_begin_ && index < big_begin_ + big_;
    }
    bool big_first_ = true;
    Eigen::Index big_begin_ = 0, big_ = 0, small_begin_ = 0, small_ = 0;
    Eigen::VectorXd big_counts_, small_counts_;
    Eigen::MatrixXd cross_;  // observation counts of each (big level, small level)
    Eigen::ArrayXd big_diagonal_, big_root_;
    double cross_scale_ = 0.0, log_det_ = 0.0;
    Eigen::MatrixXd weighted_, schur_matrix_;
    Eigen::MatrixXd distinct_rows_;           // the distinct rows of cross_
    std::vector<Eigen::Index> group_member_;  // a row of cross_ equal to each
    Eigen::VectorXd group_size_;              // how many rows equal each
    Eigen::LLT<Eigen::MatrixXd> schur_;
};

// The largest dense cross block (levels x levels) the two-intercept factor keeps; beyond
// it (10^4 participants x 2000 stimuli) the sparse Cholesky takes over.
constexpr double kLargestCrossBlock = 2e7;

// The model's fixed parts (Z, cross products) and the profiled deviance at a theta.
// Each evaluation leaves its solution (beta, u, r^2, log-determinants) in the members.
class ProfiledDeviance {
public:
    explicit ProfiledDeviance(const LmmSpec& spec) : spec_(spec), reml_(spec.reml) {
        n_ = spec.y.size();
        p_ = spec.fixed.x.cols();
        build_z();
        const SparseMatrix zt = z_.transpose();
        ztz_ = zt * z_;
        ztx_ = zt * spec.fixed.x;
        zty_ = zt * spec.y;
        xtx_ = spec.fixed.x.transpose() * spec.fixed.x;
        xty_ = spec.fixed.x.transpose() * spec.y;
        for (const auto& term : spec.random) {
            const auto q = term.z.cols();
            for (Eigen::Index c = 0; c < q; ++c)
                for (Eigen::Index r = c; r < q; ++r)
                    lower_bound_.push_back(r == c ? 0.0 : -HUGE_VAL);
        }
        prepare_scalar_terms();
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

    // Random intercepts only (every term one column, the rating studies' case): Lambda
    // is diagonal, so Lambda'Z'Z Lambda + I has Z'Z's pattern and each value is a
    // product; filled in place instead of by sparse products (half the time of a fit).
    void prepare_scalar_terms() {
        scalar_ = std::all_of(spec_.random.begin(), spec_.random.end(),
                              [](const RandomTerm& t) { return t.z.cols() == 1; });
        if (!scalar_) return;
        Eigen::Index offset = 0;
        column_theta_.resize(std::size_t(z_.cols()));
        for (std::size_t k = 0; k < spec_.random.size(); ++k) {
            const auto levels = Eigen::Index(spec_.random[k].group.levels.size());
            for (Eigen::Index l = 0; l < levels; ++l)
                column_theta_[std::size_t(offset + l)] = int(k);
            offset += levels;
        }
        if (spec_.random.size() == 2) {
            const auto first = Eigen::Index(spec_.random[0].group.levels.size());
            if (double(first) * double(z_.cols() - first) <= kLargestCrossBlock) {
                two_intercepts_.emplace(ztz_, first);
                return;
            }
        }
        scaled_ = ztz_;
        scaled_.makeCompressed();
        cholesky_.analyzePattern(scaled_);
        analysed_ = true;
        pattern_nonzeros_ = scaled_.nonZeros();
    }

    // Random intercepts only: Lambda's diagonal, each column's term's theta.
    Eigen::VectorXd lambda_diagonal_of(const std::vector<double>& theta) const {
        Eigen::VectorXd diagonal(z_.cols());
        for (Eigen::Index c = 0; c < z_.cols(); ++c)
            diagonal[c] = theta[std::size_t(column_theta_[std::size_t(c)])];
        return diagonal;
    }

    void fill_scalar(const std::vector<double>& theta, Eigen::VectorXd& lambda_diagonal) {
        lambda_diagonal = lambda_diagonal_of(theta);
        const double* from = ztz_.valuePtr();
        double* to = scaled_.valuePtr();
        for (Eigen::Index c = 0; c < ztz_.outerSize(); ++c)
            for (auto k = ztz_.outerIndexPtr()[c]; k < ztz_.outerIndexPtr()[c + 1]; ++k) {
                const auto r = ztz_.innerIndexPtr()[k];
                to[k] = lambda_diagonal[r] * from[k] * lambda_diagonal[c] +
                        (r == c ? 1.0 : 0.0);
            }
    }

    void solve(const std::vector<double>& theta) {
        SparseMatrix lam, lamt;
        Eigen::VectorXd lambda_diagonal;
        Eigen::MatrixXd lt_ztx;
        Eigen::VectorXd lt_zty;
        if (two_intercepts_) {
            solve_two_intercepts(theta);
            return;
        }
        if (scalar_) {
            fill_scalar(theta, lambda_diagonal);
            cholesky_.factorize(scaled_);
            lt_ztx = lambda_diagonal.asDiagonal() * ztx_;
            lt_zty = lambda_diagonal.cwiseProduct(zty_);
        } else {
            lam = lambda(theta);
            lamt = lam.transpose();
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
            lt_ztx = lamt * ztx_;
            lt_zty = lamt * zty_;
        }
        log_det_l2_ =
            2.0 * cholesky_.matrixL().nestedExpression().diagonal().array().log().sum();

        const Eigen::MatrixXd c_zx =
            cholesky_.matrixL().solve(cholesky_.permutationP() * lt_ztx);
        const Eigen::VectorXd c_u =
            cholesky_.matrixL().solve(cholesky_.permutationP() * lt_zty);
        solve_fixed(c_zx, c_u);
        const Eigen::VectorXd u =
            cholesky_.permutationPinv() *
            Eigen::VectorXd(cholesky_.matrixU().solve(c_u - c_zx * beta_));
        const Eigen::VectorXd b = scalar_
                                      ? Eigen::VectorXd(lambda_diagonal.cwiseProduct(u))
                                      : Eigen::VectorXd(lam * u);
        finish(u, b);
    }

    void solve_two_intercepts(const std::vector<double>& theta) {
        TwoInterceptFactor& factor = *two_intercepts_;
        factor.factorize(theta[0], theta[1]);
        log_det_l2_ = factor.log_det();
        const Eigen::VectorXd lambda_diagonal = lambda_diagonal_of(theta);
        Eigen::MatrixXd rhs(z_.cols(), p_ + 1);
        rhs.col(0) = lambda_diagonal.cwiseProduct(zty_);
        rhs.rightCols(p_) = lambda_diagonal.asDiagonal() * ztx_;
        const Eigen::MatrixXd forward = factor.forward(rhs);
        const Eigen::VectorXd c_u = forward.col(0);
        const Eigen::MatrixXd c_zx = forward.rightCols(p_);
        solve_fixed(c_zx, c_u);
        const Eigen::VectorXd u = factor.backward(c_u - c_zx * beta_);
        finish(u, lambda_diagonal.cwiseProduct(u));
    }

    // R_X from X'X - R_ZX'R_ZX, and beta.
    void solve_fixed(const Eigen::MatrixXd& c_zx, const Eigen::VectorXd& c_u) {
        const Eigen::MatrixXd rxtrx = xtx_ - c_zx.transpose() * c_zx;
        rx_.compute(rxtrx);
        rx_ok_ = rx_.info() == Eigen::Success;
        const Eigen::MatrixXd& rx_factor = rx_.matrixLLT();
        log_det_rx2_ = 2.0 * rx_factor.diagonal().array().log().sum();
        beta_ = rx_.solve(xty_ - c_zx.transpose() * c_u);
    }

    // The penalised residual sum of squares from the spherical effects u and b = Lambda
    // u.
    void finish(const Eigen::VectorXd& u, const Eigen::VectorXd& b) {
        residual_ = spec_.y;
        residual_.noalias() -= spec_.fixed.x * beta_;
        residual_.noalias() -= z_ * b;
        r2_ = residual_.squaredNorm() + u.squaredNorm();
    }

    const LmmSpec& spec_;
    bool reml_;
    Eigen::Index n_ = 0, p_ = 0;
    SparseMatrix z_, ztz_;
    Eigen::MatrixXd ztx_, xtx_;
    Eigen::VectorXd zty_, xty_;
    std::vector<double> lower_bound_;
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> cholesky_;
    bool analysed_ = false;
    bool scalar_ = false;
    std::vector<int> column_theta_;  // scalar terms: the theta of each column of Z
    SparseMatrix scaled_;            // scalar terms: Lambda'Z'Z Lambda + I, in place
    std::optional<TwoInterceptFactor> two_intercepts_;
    Eigen::VectorXd residual_;  // kept between evaluations (n long)
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

Optimum minimise(ProfiledDeviance& deviance, Convergence convergence,
                 const std::vector<double>& start) {
    const std::size_t k = deviance.theta_size();
    Optimum best;
    best.theta.assign(k, 0.0);
    // lme4's start: identity factors.
    const auto& lower = deviance.lower_bounds();
    for (std::size_t i = 0; i < k; ++i) best.theta[i] = lower[i] == 0.0 ? 1.0 : 0.0;
    if (start.size() == k)
        for (std::size_t i = 0; i < k; ++i) best.theta[i] = std::max(start[i], lower[i]);
    nlopt::opt optimiser(nlopt::LN_BOBYQA, unsigned(k));
    optimiser.set_lower_bounds(lower);
    if (convergence == Convergence::lme4_default) {
        // lme4's nloptwrap defaults, with nloptr's own xtol_rel.
        optimiser.set_ftol_abs(1e-8);
        optimiser.set_xtol_abs(1e-8);
        optimiser.set_xtol_rel(1e-4);
    } else {
        optimiser.set_xtol_rel(convergence == Convergence::likelihood ? 1e-7 : 1e-10);
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
    const Optimum optimum = minimise(deviance, spec.convergence, spec.start_theta);

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
    const auto p = beta.size();
    if (!spec.satterthwaite_tests) {
        for (Eigen::Index j = 0; j < p; ++j)
            fit.fixed.push_back({spec.fixed.names[std::size_t(j)],
                                 beta[j],
                                 std::sqrt(fit.fixed_covariance(j, j)),
                                 {},
                                 {},
                                 {}});
        return fit;
    }
    const Satterthwaite satterthwaite(deviance, fit.theta, fit.sigma, fit.notes);
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
    for (LmmSpec* spec : {&reduced, &full}) {
        spec->satterthwaite_tests = false;
        if (spec->convergence == Convergence::optimum)
            spec->convergence = Convergence::likelihood;
    }
    const LmmFit large = fit_lmm(full);
    reduced.start_theta = large.theta;
    const LmmFit small = fit_lmm(reduced);
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
