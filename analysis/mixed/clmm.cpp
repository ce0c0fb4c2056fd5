#include "analysis/mixed/clmm.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>
#include <nlopt.hpp>
#include <numeric>
#include <thread>

#include "analysis/data/long_table.h"  // InputError

namespace lucent::analysis::mixed {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Bigger than any objective an evaluation can return; BOBYQA needs finite values.
constexpr double kRejected = 1e300;

// ---------------------------------------------------------------------------------------
// Links: the distribution function F (logistic or normal), its density f and slope f'.

// One observation's log-probability log(F(upper) - F(lower)) and its derivatives in the
// two bounds; eta (the linear predictor) enters both as -eta.
struct ObservationTerms {
    double log_p = 0;
    double d_upper = 0, d_lower = 0;                 // first derivatives
    double d2_upper = 0, d2_lower = 0, d2_both = 0;  // second derivatives
    double d_eta() const { return -(d_upper + d_lower); }
    double d2_eta() const { return d2_upper + 2 * d2_both + d2_lower; }
};

// F, 1 - F, f and f' at one bound, with one exp (logit) or one erfc and exp (probit).
struct BoundTerms {
    double cdf = 0, upper_tail = 1, pdf = 0, pdf_slope = 0;
};

BoundTerms bound_terms(Link link, double z) {
    BoundTerms b;
    if (std::isinf(z)) {
        b.cdf = z > 0 ? 1.0 : 0.0;
        b.upper_tail = 1.0 - b.cdf;
        return b;
    }
    if (link == Link::Probit) {
        b.cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
        b.upper_tail = 0.5 * std::erfc(z / std::sqrt(2.0));
        b.pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
        b.pdf_slope = -z * b.pdf;
        return b;
    }
    const double e = std::exp(-std::abs(z));  // no overflow on either side
    const double near = 1.0 / (1.0 + e), far = e * near;
    b.cdf = z >= 0 ? near : far;
    b.upper_tail = z >= 0 ? far : near;
    b.pdf = b.cdf * b.upper_tail;
    b.pdf_slope = b.pdf * (b.upper_tail - b.cdf);
    return b;
}

// False when the probability underflows (the parameters are far off).
bool observation_terms(Link link, double lower, double upper, ObservationTerms& t) {
    const BoundTerms lo = bound_terms(link, lower), hi = bound_terms(link, upper);
    // Through the upper tails when both bounds are far right (no cancellation).
    const double p = lower > 0 ? lo.upper_tail - hi.upper_tail : hi.cdf - lo.cdf;
    if (!(p > 0)) return false;
    const double inverse = 1.0 / p;
    const double a = hi.pdf * inverse, b = lo.pdf * inverse;
    t.log_p = std::log(p);
    t.d_upper = a;
    t.d_lower = -b;
    t.d2_upper = hi.pdf_slope * inverse - a * a;
    t.d2_lower = -lo.pdf_slope * inverse - b * b;
    t.d2_both = a * b;
    return true;
}

// Neumaier's compensated sum: the log-likelihood of thousands of observations to
// rounding level (plain summation leaves ~1e-11 of noise, which finite differences of
// the objective amplify by 1 / step^2).
inline void add_compensated(double& sum, double& compensation, double x) {
    const double t = sum + x;
    compensation += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
}

double max_abs(const VectorXd& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }

std::string in_quotes(const std::string& s) { return "'" + s + "'"; }

// ---------------------------------------------------------------------------------------
// The model as fitted: used categories, kept fixed columns, identifiable groupings.

struct Grouping {
    std::string name;
    std::vector<std::string> levels;
    std::vector<int> codes;
};

struct Problem {
    Link link = Link::Logit;
    ClmmModes modes = ClmmModes::AsR;
    bool precise_standard_errors = true;
    bool lagged_log_det = false;          // as clmm with a single random term (see as_r)
    std::vector<std::string> categories;  // used response levels
    std::vector<int> y;                   // 0 .. categories - 1
    MatrixXd x;                           // kept fixed columns
    std::vector<std::string> x_names;
    std::vector<int> x_source_columns;  // index in the spec's design
    std::vector<Grouping> groupings;    // identifiable ones
    std::vector<int> grouping_source;   // index in spec.random_intercepts

    int n() const { return int(y.size()); }
    int thresholds() const { return int(categories.size()) - 1; }
    int effects() const { return int(x.cols()); }
    int fixed_parameters() const { return thresholds() + effects(); }
};

void drop_unused_categories(const ClmmSpec& spec, Problem& problem,
                            std::vector<std::string>& notes) {
    const auto& levels = spec.response.levels;
    std::vector<int> count(levels.size(), 0), new_code(levels.size(), -1);
    for (int code : spec.response.codes) ++count[std::size_t(code)];
    std::vector<std::string> unused;
    for (std::size_t l = 0; l < levels.size(); ++l) {
        if (count[l] == 0) {
            unused.push_back(in_quotes(levels[l]));
            continue;
        }
        new_code[l] = int(problem.categories.size());
        problem.categories.push_back(levels[l]);
    }
    for (int code : spec.response.codes) problem.y.push_back(new_code[std::size_t(code)]);
    for (const auto& level : unused)
        notes.push_back("rating category " + level + " of " +
                        in_quotes(spec.response.name) +
                        " was never used: it is dropped from the response levels (its "
                        "threshold cannot be estimated)");
}

// Keeps the fixed columns that add a direction to the constant (which the thresholds
// absorb) and the columns before them, as R drops aliased coefficients. Returns an
// orthonormal basis of [1, kept columns] for the grouping checks.
MatrixXd keep_independent_columns(const ClmmSpec& spec, Problem& problem,
                                  std::vector<std::string>& dropped,
                                  std::vector<std::string>& notes) {
    const auto n = Eigen::Index(problem.n());
    const MatrixXd& x = spec.fixed.x;
    std::vector<VectorXd> basis{VectorXd::Constant(n, 1.0 / std::sqrt(double(n)))};
    std::vector<int> kept;
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
        const std::string& name = spec.fixed.names[std::size_t(c)];
        VectorXd residual = x.col(c);
        const double norm = residual.norm();
        for (int pass = 0; pass < 2; ++pass)  // twice: Gram-Schmidt loses orthogonality
            for (const auto& q : basis) residual -= q.dot(residual) * q;
        if (norm > 0 && residual.norm() > 1e-9 * norm) {
            basis.push_back(residual / residual.norm());
            kept.push_back(int(c));
            continue;
        }
        dropped.push_back(name);
        const double spread = (x.col(c).array() - x.col(c).mean()).matrix().norm();
        if (norm == 0)
            notes.push_back("fixed column " + in_quotes(name) + " is all zero: dropped");
        else if (spread <= 1e-9 * norm)
            notes.push_back("fixed column " + in_quotes(name) +
                            " is constant: the thresholds absorb it; dropped");
        else
            notes.push_back("fixed column " + in_quotes(name) +
                            " is collinear with the columns before it: dropped");
    }
    problem.x.resize(n, Eigen::Index(kept.size()));
    for (std::size_t k = 0; k < kept.size(); ++k) {
        problem.x.col(Eigen::Index(k)) = x.col(kept[k]);
        problem.x_names.push_back(spec.fixed.names[std::size_t(kept[k])]);
    }
    problem.x_source_columns = kept;
    MatrixXd q(n, Eigen::Index(basis.size()));
    for (std::size_t k = 0; k < basis.size(); ++k) q.col(Eigen::Index(k)) = basis[k];
    return q;
}

// A grouping whose indicators lie in the span of [1, X] has a variance the data cannot
// tell apart from the thresholds and effects (one level; one stimulus per level).
bool confounded_with_fixed(const FactorColumn& grouping, const MatrixXd& basis) {
    MatrixXd projection =
        MatrixXd::Zero(Eigen::Index(grouping.levels.size()), basis.cols());
    std::vector<double> count(grouping.levels.size(), 0.0);
    for (std::size_t i = 0; i < grouping.codes.size(); ++i) {
        projection.row(grouping.codes[i]) += basis.row(Eigen::Index(i));
        count[std::size_t(grouping.codes[i])] += 1;
    }
    for (std::size_t l = 0; l < count.size(); ++l)
        if (count[l] > 0 &&
            count[l] - projection.row(Eigen::Index(l)).squaredNorm() > 1e-8 * count[l])
            return false;
    return true;
}

// Only the levels that occur, in their order (a grouping's empty levels carry nothing).
Grouping used_levels(const FactorColumn& factor) {
    Grouping g;
    g.name = factor.name;
    std::vector<int> new_code(factor.levels.size(), -1);
    for (int code : factor.codes) new_code[std::size_t(code)] = 0;
    for (std::size_t l = 0; l < factor.levels.size(); ++l)
        if (new_code[l] == 0) {
            new_code[l] = int(g.levels.size());
            g.levels.push_back(factor.levels[l]);
        }
    for (int code : factor.codes) g.codes.push_back(new_code[std::size_t(code)]);
    return g;
}

void note_constant_raters(const Grouping& g, const std::vector<int>& y,
                          const std::vector<std::string>& categories,
                          std::vector<std::string>& notes) {
    std::vector<int> first(g.levels.size(), -1), count(g.levels.size(), 0);
    std::vector<bool> constant(g.levels.size(), true);
    for (std::size_t i = 0; i < y.size(); ++i) {
        const auto l = std::size_t(g.codes[i]);
        if (count[l]++ == 0) first[l] = y[i];
        if (y[i] != first[l]) constant[l] = false;
    }
    for (std::size_t l = 0; l < g.levels.size(); ++l)
        if (constant[l] && count[l] >= 2)
            notes.push_back(g.name + " " + in_quotes(g.levels[l]) +
                            " gave the same rating (" +
                            in_quotes(categories[std::size_t(first[l])]) + ") to all " +
                            std::to_string(count[l]) +
                            " of their observations: their random intercept rests on "
                            "the shrinkage of the variance");
}

void check_sizes(const ClmmSpec& spec) {
    const std::size_t n = spec.response.size();
    if (std::size_t(spec.fixed.x.rows()) != n && spec.fixed.x.size() != 0)
        throw InputError("clmm: the fixed design has " +
                         std::to_string(spec.fixed.x.rows()) + " rows for " +
                         std::to_string(n) + " responses");
    if (spec.fixed.names.size() != std::size_t(spec.fixed.x.cols()))
        throw InputError("clmm: the fixed design's names do not match its columns");
    for (const auto& g : spec.random_intercepts)
        if (g.size() != n)
            throw InputError("clmm: grouping '" + g.name + "' has " +
                             std::to_string(g.size()) + " values for " +
                             std::to_string(n) + " responses");
    if (spec.random_intercepts.size() > 2)
        throw InputError("clmm: at most two (crossed) random-intercept groupings");
}

// ---------------------------------------------------------------------------------------
// clm: Newton-Raphson on the exact log-likelihood. Parameters [thresholds, effects].

struct LogLikelihood {
    double value = -kInfinity;
    VectorXd gradient;
    MatrixXd hessian;
};

bool thresholds_increasing(const VectorXd& par, int thresholds) {
    for (int j = 1; j < thresholds; ++j)
        if (!(par[j] > par[j - 1])) return false;
    return true;
}

// The exact clm log-likelihood with its gradient and Hessian (an offset per observation
// lets the Laplace step reuse it with the random effects fixed).
LogLikelihood clm_log_likelihood(const Problem& problem, const VectorXd& par) {
    const int k_thr = problem.thresholds(), p = problem.effects(), n = problem.n();
    LogLikelihood result;
    if (!thresholds_increasing(par, k_thr)) return result;
    const VectorXd eta = problem.x * par.tail(p);
    VectorXd d_eta(n), d2_eta(n);
    VectorXd g_thr = VectorXd::Zero(k_thr);
    MatrixXd h_thr = MatrixXd::Zero(k_thr, k_thr), h_cross = MatrixXd::Zero(k_thr, p);
    double sum = 0;
    ObservationTerms t;
    for (int i = 0; i < n; ++i) {
        const int k = problem.y[std::size_t(i)];
        const double upper = k < k_thr ? par[k] - eta[i] : kInfinity;
        const double lower = k > 0 ? par[k - 1] - eta[i] : -kInfinity;
        if (!observation_terms(problem.link, lower, upper, t)) return result;
        sum += t.log_p;
        d_eta[i] = t.d_eta();
        d2_eta[i] = t.d2_eta();
        const auto row = problem.x.row(i);
        if (k < k_thr) {
            g_thr[k] += t.d_upper;
            h_thr(k, k) += t.d2_upper;
            h_cross.row(k) -= (t.d2_upper + t.d2_both) * row;
        }
        if (k > 0) {
            g_thr[k - 1] += t.d_lower;
            h_thr(k - 1, k - 1) += t.d2_lower;
            h_cross.row(k - 1) -= (t.d2_lower + t.d2_both) * row;
        }
        if (k > 0 && k < k_thr) {
            h_thr(k, k - 1) += t.d2_both;
            h_thr(k - 1, k) += t.d2_both;
        }
    }
    result.value = sum;
    result.gradient.resize(k_thr + p);
    result.gradient << g_thr, problem.x.transpose() * d_eta;
    result.hessian.resize(k_thr + p, k_thr + p);
    result.hessian.topLeftCorner(k_thr, k_thr) = h_thr;
    result.hessian.topRightCorner(k_thr, p) = h_cross;
    result.hessian.bottomLeftCorner(p, k_thr) = h_cross.transpose();
    result.hessian.bottomRightCorner(p, p) =
        problem.x.transpose() * d2_eta.asDiagonal() * problem.x;
    return result;
}

// Starting thresholds: the quantiles of the cumulative proportions (no effects).
VectorXd clm_start(const Problem& problem) {
    const int k_thr = problem.thresholds();
    VectorXd par = VectorXd::Zero(problem.fixed_parameters());
    std::vector<double> count(std::size_t(k_thr + 1), 0.0);
    for (int k : problem.y) count[std::size_t(k)] += 1;
    double cumulative = 0;
    for (int j = 0; j < k_thr; ++j) {
        cumulative += count[std::size_t(j)];
        const double share = cumulative / problem.n();
        par[j] =
            problem.link == Link::Probit
                ? boost::math::quantile(boost::math::normal_distribution<double>(), share)
                : std::log(share / (1 - share));
    }
    return par;
}

struct ClmResult {
    VectorXd par;
    LogLikelihood at;
    int iterations = 0;
    bool converged = false;
};

ClmResult fit_clm_newton(const Problem& problem) {
    ClmResult r;
    r.par = clm_start(problem);
    r.at = clm_log_likelihood(problem, r.par);
    for (r.iterations = 0; r.iterations < 200; ++r.iterations) {
        Eigen::LDLT<MatrixXd> information(-r.at.hessian);
        VectorXd step = information.solve(r.at.gradient);
        if (information.info() != Eigen::Success || !step.allFinite() ||
            step.dot(r.at.gradient) <= 0)
            step = r.at.gradient;  // not a descent direction: steepest ascent
        const bool small_step = max_abs(step) < 1e-10;
        double factor = 1;
        LogLikelihood next;
        for (int halving = 0; halving < 60; ++halving, factor /= 2) {
            next = clm_log_likelihood(problem, r.par + factor * step);
            if (next.value >= r.at.value - 1e-12 * std::abs(r.at.value)) break;
        }
        if (!(next.value >= r.at.value - 1e-12 * std::abs(r.at.value))) break;
        const double gain = next.value - r.at.value;
        r.par += factor * step;
        r.at = std::move(next);
        // Converged when the step vanished, or (separation: the effect runs off with no
        // end) when nothing more is gained and the gradient is zero to rounding.
        if (small_step || (std::abs(gain) < 1e-13 * (1 + std::abs(r.at.value)) &&
                           max_abs(r.at.gradient) < 1e-8)) {
            r.converged = true;
            break;
        }
    }
    return r;
}

// Covariance from an information matrix (the negative Hessian of log L) over the
// parameters marked `keep`; the rest get 0. Empty when it is not positive definite.
VectorXd standard_errors(const MatrixXd& information, const std::vector<bool>& keep) {
    std::vector<int> idx;
    for (std::size_t j = 0; j < keep.size(); ++j)
        if (keep[j]) idx.push_back(int(j));
    MatrixXd sub(Eigen::Index(idx.size()), Eigen::Index(idx.size()));
    for (std::size_t a = 0; a < idx.size(); ++a)
        for (std::size_t b = 0; b < idx.size(); ++b)
            sub(Eigen::Index(a), Eigen::Index(b)) = information(idx[a], idx[b]);
    VectorXd se = VectorXd::Zero(Eigen::Index(keep.size()));
    if (idx.empty()) return se;
    Eigen::LLT<MatrixXd> chol(sub);
    if (chol.info() != Eigen::Success) return VectorXd();
    const MatrixXd cov = chol.solve(MatrixXd::Identity(sub.rows(), sub.cols()));
    for (std::size_t a = 0; a < idx.size(); ++a) {
        const double v = cov(Eigen::Index(a), Eigen::Index(a));
        if (!(v > 0) || !std::isfinite(v)) return VectorXd();
        se[idx[a]] = std::sqrt(v);
    }
    return se;
}

// Complete separation: a parameter that went far out on the linear-predictor scale with a
// standard error that makes it meaningless has no finite maximum likelihood estimate.
std::vector<bool> runs_to_infinity(const Problem& problem, const VectorXd& par,
                                   const MatrixXd& information) {
    const int k_thr = problem.thresholds(), m = int(par.size());
    std::vector<bool> infinite(std::size_t(m), false);
    // Each parameter's scale on the linear predictor: thresholds 1, effects the range.
    VectorXd scale = VectorXd::Ones(m);
    for (int c = 0; c < problem.effects(); ++c)
        scale[k_thr + c] = problem.x.col(c).maxCoeff() - problem.x.col(c).minCoeff();
    Eigen::SelfAdjointEigenSolver<MatrixXd> eigen(information);
    const VectorXd values = eigen.eigenvalues();
    const double largest = std::max(values.cwiseAbs().maxCoeff(), 1e-300);
    for (int e = 0; e < m; ++e) {
        // A well-determined direction, relative to the best one and in itself: when
        // every parameter runs off (a saturated model, one rating per level) the whole
        // information matrix is tiny, and only the absolute test sees it.
        if (values[e] > 1e-7 * largest && values[e] > 1e-8) continue;
        const VectorXd direction = eigen.eigenvectors().col(e);
        for (int j = 0; j < m; ++j)
            if (std::abs(direction[j]) > 0.1 && std::abs(par[j]) * scale[j] > 5)
                infinite[std::size_t(j)] = true;
    }
    return infinite;
}

// ---------------------------------------------------------------------------------------
// The Laplace approximation with one or two (crossed) random-intercept groupings.
// Parameters [thresholds, effects, tau per grouping]; modes u = b / tau, [u_a, u_b] where
// grouping a (the one with more levels) is eliminated by its diagonal block.

// Eliminate the grouping with more levels; the Schur complement is dense on the other,
// so its size is the smaller count. Tau follows this order among the parameters.
std::vector<int> elimination_order(const Problem& problem, std::vector<int> active) {
    auto levels = [&](int g) { return problem.groupings[std::size_t(g)].levels.size(); };
    if (active.size() == 2 && levels(active[0]) < levels(active[1]))
        std::swap(active[0], active[1]);
    return active;
}

class LaplaceObjective {
public:
    // `active`: groupings in elimination_order.
    LaplaceObjective(const Problem& problem, std::vector<int> active, ClmmModes mode,
                     bool lagged_log_det)
        : problem_(problem),
          active_(std::move(active)),
          mode_(mode),
          lagged_log_det_(lagged_log_det) {
        codes_a_ = &problem.groupings[std::size_t(active_[0])].codes;
        q_a_ = levels_of(active_[0]);
        if (active_.size() == 2) {
            codes_b_ = &problem.groupings[std::size_t(active_[1])].codes;
            q_b_ = levels_of(active_[1]);
            index_cells();
        }
        // A factor of nothing, so that copying the objective (one per thread) never
        // copies Eigen's uninitialised status of a factor not computed yet (UBSan).
        schur_factor_.compute(MatrixXd());
    }

    int modes() const { return q_a_ + q_b_; }

    // -log L at `par`; `u` is the start of the inner Newton and receives the modes.
    // kRejected when the parameters are outside the model (thresholds not increasing).
    double operator()(const VectorXd& par, VectorXd& u) {
        ++evaluations;
        const int k_thr = problem_.thresholds();
        if (!thresholds_increasing(par, k_thr)) return kRejected;
        offset_ = problem_.x * par.segment(k_thr, problem_.effects());
        tau_a_ = par[problem_.fixed_parameters()];
        tau_b_ = q_b_ ? par[problem_.fixed_parameters() + 1] : 0.0;
        if (u.size() != modes()) u = VectorXd::Zero(modes());
        if (mode_ == ClmmModes::AsR) return as_r(par, u);
        if (!accumulate(par, u)) return kRejected;
        for (int iteration = 0; iteration < 100; ++iteration) {
            const VectorXd step = solve(gradient_);
            const bool small = max_abs(step) < 1e-9;
            const double before = penalised_;
            double factor = 1;
            for (int halving = 0;; ++halving, factor /= 2) {
                if (halving == 40) return kRejected;
                if (accumulate(par, u - factor * step) &&
                    penalised_ <= before + 1e-11 * (1 + std::abs(before)))
                    break;
            }
            u -= factor * step;
            // After a tiny step one more Newton step has put u^ at rounding level
            // (quadratic convergence): the value is smooth for finite differences.
            if (small) break;
        }
        return penalised_ + 0.5 * log_det();
    }

    int evaluations = 0;

private:
    // clmm's inner Newton (ordinal 2022.11): from u = 0, with its step halving, stopped
    // once max|gradient| < 1e-4 (clmm.control's gradTol). With one grouping (its C
    // routine NRalgv3) the log-determinant is that of the Hessian of the last Newton
    // step, taken before the step (1s when no step was taken); with two (update.u) it is
    // recomputed at the final modes.
    double as_r(const VectorXd& par, VectorXd& u) {
        u.setZero();
        if (!accumulate(par, u)) return kRejected;
        double log_det_of_last_step = 0;
        double factor = 1;
        for (int iteration = 0; iteration < 50; ++iteration) {
            if (max_abs(gradient_) < 1e-4) break;
            const VectorXd step = solve(gradient_);
            log_det_of_last_step = log_det();
            const double before = penalised_;
            VectorXd trial = u - factor * step;
            bool valid = accumulate(par, trial);
            for (int line = 0; !valid || penalised_ > before; ++line) {
                if (line == 50) return kRejected;
                factor /= 2;
                trial += factor * step;
                valid = accumulate(par, trial);
            }
            u = trial;
            factor = std::min(1.0, 2 * factor);
        }
        return penalised_ + 0.5 * (lagged_log_det_ ? log_det_of_last_step : log_det());
    }

    int levels_of(int g) const {
        return int(problem_.groupings[std::size_t(g)].levels.size());
    }

    // The distinct (a, b) pairs with observations, grouped by a.
    void index_cells() {
        cell_of_.resize(codes_a_->size());
        std::vector<std::pair<long, int>> keys;
        for (std::size_t i = 0; i < codes_a_->size(); ++i)
            keys.emplace_back(long((*codes_a_)[i]) * q_b_ + (*codes_b_)[i], int(i));
        std::sort(keys.begin(), keys.end());
        cell_start_.assign(std::size_t(q_a_ + 1), 0);
        long previous = -1;
        for (const auto& [key, i] : keys) {
            if (key != previous) {
                cell_b_.push_back(int(key % q_b_));
                ++cell_start_[std::size_t(key / q_b_) + 1];
                previous = key;
            }
            cell_of_[std::size_t(i)] = int(cell_b_.size()) - 1;
        }
        for (int a = 0; a < q_a_; ++a) cell_start_[std::size_t(a + 1)] += cell_start_[a];
        cell_weight_.resize(Eigen::Index(cell_b_.size()));
    }

    // Observations first .. first + count - 1 (a block that stays in cache): each one's
    // log-probability, first derivative d and weight w = -second derivative in eta at the
    // modes `u`, into log_p_, d_, w_ [0, count). False when a probability underflows.
    bool observation_derivatives(const VectorXd& par, const VectorXd& u, int first,
                                 int count) {
        const int k_thr = problem_.thresholds();
        if (problem_.link != Link::Logit) {
            ObservationTerms t;
            for (int j = 0; j < count; ++j) {
                const int i = first + j, k = problem_.y[std::size_t(i)];
                const double eta = linear_predictor(i, u);
                const double upper = k < k_thr ? par[k] - eta : kInfinity;
                const double lower = k > 0 ? par[k - 1] - eta : -kInfinity;
                if (!observation_terms(problem_.link, lower, upper, t)) return false;
                log_p_[j] = t.log_p;
                d_[j] = t.d_eta();
                w_[j] = -t.d2_eta();
            }
            return true;
        }
        // Logit, vectorised over the block: observation_terms' arithmetic, with a missing
        // bound (lowest or highest category) at 0 and masked out.
        for (int j = 0; j < count; ++j) {
            const int i = first + j, k = problem_.y[std::size_t(i)];
            const double eta = linear_predictor(i, u);
            upper_[j] = k < k_thr ? par[k] - eta : 0.0;
            lower_[j] = k > 0 ? par[k - 1] - eta : 0.0;
        }
        const auto has_upper = has_upper_.segment(first, count);
        const auto has_lower = has_lower_.segment(first, count);
        const auto upper = upper_.head(count), lower = lower_.head(count);
        auto e = e_.head(count), r = r_.head(count);
        auto cdf_hi = cdf_hi_.head(count), tail_hi = tail_hi_.head(count),
             pdf_hi = pdf_hi_.head(count), slope_hi = slope_hi_.head(count);
        auto cdf_lo = cdf_lo_.head(count), tail_lo = tail_lo_.head(count),
             pdf_lo = pdf_lo_.head(count), slope_lo = slope_lo_.head(count);
        // Upper bound: F, 1 - F, f, f'.
        e = (-upper.abs()).exp();
        r = (1.0 + e).inverse();
        split_tails(upper_, count, cdf_hi_, tail_hi_);
        pdf_hi = has_upper * cdf_hi * tail_hi;
        slope_hi = pdf_hi * (tail_hi - cdf_hi);
        cdf_hi = has_upper * cdf_hi + (1.0 - has_upper);
        tail_hi = has_upper * tail_hi;
        // Lower bound.
        e = (-lower.abs()).exp();
        r = (1.0 + e).inverse();
        split_tails(lower_, count, cdf_lo_, tail_lo_);
        pdf_lo = has_lower * cdf_lo * tail_lo;
        slope_lo = pdf_lo * (tail_lo - cdf_lo);
        cdf_lo = has_lower * cdf_lo;
        tail_lo = has_lower * tail_lo + (1.0 - has_lower);
        // p, through the upper tails when both bounds are far right (no cancellation).
        for (int j = 0; j < count; ++j)  // plain loops: the compiler vectorises them
            e_[j] = lower_[j] > 0 && has_lower_[first + j] > 0 ? tail_lo_[j] - tail_hi_[j]
                                                               : cdf_hi_[j] - cdf_lo_[j];
        if (!(e > 0).all()) return false;
        log_p_.head(count) = e.log();
        r = e.inverse();
        cdf_hi = pdf_hi * r;  // a = d log p / d upper
        cdf_lo = pdf_lo * r;  // b = -d log p / d lower
        d_.head(count) = cdf_lo - cdf_hi;
        w_.head(count) = -(slope_hi * r - cdf_hi.square() + 2.0 * cdf_hi * cdf_lo -
                           slope_lo * r - cdf_lo.square());
        return true;
    }

    double linear_predictor(int i, const VectorXd& u) const {
        const int a = (*codes_a_)[std::size_t(i)];
        return offset_[i] + tau_a_ * u[a] +
               (q_b_ ? tau_b_ * u[q_a_ + (*codes_b_)[std::size_t(i)]] : 0.0);
    }

    static constexpr int kBlock = 256;

    // F and 1 - F from e = exp(-|z|) and r = 1 / (1 + e) (in e_, r_).
    void split_tails(const Eigen::ArrayXd& z, int count, Eigen::ArrayXd& cdf,
                     Eigen::ArrayXd& tail) const {
        for (int j = 0; j < count; ++j) {
            const double near = r_[j], far = e_[j] * r_[j];
            cdf[j] = z[j] >= 0 ? near : far;
            tail[j] = z[j] >= 0 ? far : near;
        }
    }

    void prepare_blocks() {
        const int n = problem_.n(), k_thr = problem_.thresholds();
        has_upper_.resize(n);
        has_lower_.resize(n);
        for (int i = 0; i < n; ++i) {
            const int k = problem_.y[std::size_t(i)];
            has_upper_[i] = k < k_thr ? 1.0 : 0.0;
            has_lower_[i] = k > 0 ? 1.0 : 0.0;
        }
        for (Eigen::ArrayXd* block :
             {&log_p_, &d_, &w_, &upper_, &lower_, &e_, &r_, &cdf_hi_, &tail_hi_,
              &pdf_hi_, &slope_hi_, &cdf_lo_, &tail_lo_, &pdf_lo_, &slope_lo_})
            block->resize(kBlock);
    }

    // The penalised deviance -log p(y|u) + u'u/2, its gradient in u and the Hessian's
    // pieces (diagonal blocks, cell weights) at `u`. False when a probability underflows.
    bool accumulate(const VectorXd& par, const VectorXd& u) {
        const int n = problem_.n();
        gradient_ = u;
        diag_.setOnes(modes());
        if (q_b_) cell_weight_.setZero();
        if (has_upper_.size() != n) prepare_blocks();
        double sum = 0, compensation = 0;
        for (int first = 0; first < n; first += kBlock) {
            const int count = std::min(kBlock, n - first);
            if (!observation_derivatives(par, u, first, count)) return false;
            for (int j = 0; j < count; ++j) {
                const int i = first + j;
                const int a = (*codes_a_)[std::size_t(i)];
                const int b = q_b_ ? (*codes_b_)[std::size_t(i)] : 0;
                add_compensated(sum, compensation, log_p_[j]);
                const double d = d_[j], w = w_[j];
                gradient_[a] -= tau_a_ * d;
                diag_[a] += tau_a_ * tau_a_ * w;
                if (q_b_) {
                    gradient_[q_a_ + b] -= tau_b_ * d;
                    diag_[q_a_ + b] += tau_b_ * tau_b_ * w;
                    cell_weight_[cell_of_[std::size_t(i)]] += tau_a_ * tau_b_ * w;
                }
            }
        }
        penalised_ = -(sum + compensation) + 0.5 * u.squaredNorm();
        if (q_b_) factor_schur();
        return std::isfinite(penalised_);
    }

    // S = D_b - C' D_a^-1 C, with C the cell weights (a x b, sparse). A dense product
    // when C fits in memory (vectorised: 200 x 60 takes microseconds), else by rows.
    void factor_schur() {
        schur_ = diag_.tail(q_b_).asDiagonal();
        if (double(q_a_) * q_b_ <= 4e6) {
            scaled_cells_.setZero(q_a_, q_b_);
            for (int a = 0; a < q_a_; ++a) {
                const double scale = 1.0 / std::sqrt(diag_[a]);
                for (int c = cell_start_[std::size_t(a)];
                     c < cell_start_[std::size_t(a + 1)]; ++c)
                    scaled_cells_(a, cell_b_[std::size_t(c)]) = cell_weight_[c] * scale;
            }
            schur_.selfadjointView<Eigen::Lower>().rankUpdate(scaled_cells_.transpose(),
                                                              -1.0);
            schur_factor_.compute(schur_);
            return;
        }
        for (int a = 0; a < q_a_; ++a) {
            const double inv = 1.0 / diag_[a];
            for (int c1 = cell_start_[std::size_t(a)];
                 c1 < cell_start_[std::size_t(a + 1)]; ++c1) {
                const double w1 = cell_weight_[c1] * inv;
                for (int c2 = cell_start_[std::size_t(a)];
                     c2 < cell_start_[std::size_t(a + 1)]; ++c2)
                    schur_(cell_b_[std::size_t(c1)], cell_b_[std::size_t(c2)]) -=
                        w1 * cell_weight_[c2];
            }
        }
        schur_factor_.compute(schur_);
    }

    VectorXd solve(const VectorXd& rhs) const {
        VectorXd x = rhs.cwiseQuotient(diag_);
        if (!q_b_) return x;
        VectorXd rhs_b = rhs.tail(q_b_);
        for (int a = 0; a < q_a_; ++a)
            for (int c = cell_start_[std::size_t(a)]; c < cell_start_[std::size_t(a + 1)];
                 ++c)
                rhs_b[cell_b_[std::size_t(c)]] -= cell_weight_[c] * x[a];
        const VectorXd x_b = schur_factor_.solve(rhs_b);
        for (int a = 0; a < q_a_; ++a) {
            double r = rhs[a];
            for (int c = cell_start_[std::size_t(a)]; c < cell_start_[std::size_t(a + 1)];
                 ++c)
                r -= cell_weight_[c] * x_b[cell_b_[std::size_t(c)]];
            x[a] = r / diag_[a];
        }
        x.tail(q_b_) = x_b;
        return x;
    }

    double log_det() const {
        double sum = diag_.head(q_a_).array().log().sum();
        if (q_b_) sum += 2 * schur_factor_.matrixLLT().diagonal().array().log().sum();
        return sum;
    }

    const Problem& problem_;
    std::vector<int> active_;
    ClmmModes mode_;
    bool lagged_log_det_;
    const std::vector<int>* codes_a_ = nullptr;
    const std::vector<int>* codes_b_ = nullptr;
    int q_a_ = 0, q_b_ = 0;
    std::vector<int> cell_of_, cell_b_, cell_start_;
    VectorXd cell_weight_, offset_, gradient_, diag_;
    Eigen::ArrayXd log_p_, d_, w_, has_upper_, has_lower_, upper_, lower_, e_, r_,
        cdf_hi_, tail_hi_, pdf_hi_, slope_hi_, cdf_lo_, tail_lo_, pdf_lo_, slope_lo_;
    MatrixXd schur_, scaled_cells_;
    Eigen::LLT<MatrixXd> schur_factor_;
    double tau_a_ = 0, tau_b_ = 0, penalised_ = 0;
};

// Central differences at steps h and h/2, Richardson-extrapolated (error O(h^4)), over
// the parameters marked free. f must be smooth: the inner solve is at rounding level.
// With `extrapolate` false: one level (step h/2), error O(h^2), half the evaluations.
// Mixed second derivatives use the diagonal points x +- h_i e_i, x +- h_j e_j and the two
// points x +- (h_i e_i + h_j e_j) (even in h, so the extrapolation holds): 2 evaluations
// per pair instead of 4. `f_all` evaluates a list of points (in parallel).
template <class F>
void finite_difference_derivatives(F& f_all, const VectorXd& x,
                                   const std::vector<int>& free, VectorXd& gradient,
                                   MatrixXd& hessian, bool with_hessian,
                                   bool extrapolate = true) {
    const int m = int(free.size());
    const int first_level = extrapolate ? 0 : 1;
    MatrixXd step(2, m);
    std::vector<VectorXd> points;
    if (with_hessian) points.push_back(x);
    auto add = [&](int level, int i, double si, int j, double sj) {
        VectorXd y = x;
        y[free[i]] += si * step(level, i);
        if (j >= 0) y[free[j]] += sj * step(level, j);
        points.push_back(std::move(y));
    };
    for (int level = first_level; level < 2; ++level) {
        for (int j = 0; j < m; ++j)
            step(level, j) = (level ? 1e-3 : 2e-3) * std::max(1.0, std::abs(x[free[j]]));
        for (int j = 0; j < m; ++j) {
            add(level, j, 1, -1, 0);
            add(level, j, -1, -1, 0);
        }
        if (with_hessian)
            for (int j = 0; j < m; ++j)
                for (int i = 0; i < j; ++i) {
                    add(level, i, 1, j, 1);
                    add(level, i, -1, j, -1);
                }
    }
    const std::vector<double> values = f_all(points);
    std::size_t next = 0;
    const double f0 = with_hessian ? values[next++] : 0.0;
    VectorXd g[2];
    MatrixXd h[2];
    for (int level = first_level; level < 2; ++level) {
        g[level] = VectorXd::Zero(m);
        h[level] = MatrixXd::Zero(m, m);
        VectorXd plus(m), minus(m);
        for (int j = 0; j < m; ++j) {
            plus[j] = values[next++];
            minus[j] = values[next++];
            const double hj = step(level, j);
            g[level][j] = (plus[j] - minus[j]) / (2 * hj);
            h[level](j, j) = (plus[j] - 2 * f0 + minus[j]) / (hj * hj);
        }
        if (!with_hessian) continue;
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < j; ++i) {
                const double both_plus = values[next++], both_minus = values[next++];
                const double v = (both_plus + both_minus - plus[i] - minus[i] - plus[j] -
                                  minus[j] + 2 * f0) /
                                 (2 * step(level, i) * step(level, j));
                h[level](i, j) = h[level](j, i) = v;
            }
    }
    gradient = extrapolate ? VectorXd((4 * g[1] - g[0]) / 3) : g[1];
    if (with_hessian) hessian = extrapolate ? MatrixXd((4 * h[1] - h[0]) / 3) : h[1];
}

struct LaplaceResult {
    VectorXd par;  // [thresholds, effects, tau per active grouping]
    VectorXd modes;
    MatrixXd hessian;  // of -log L over the free parameters (free order)
    std::vector<int> free;
    double log_likelihood = 0;
    int evaluations = 0;
    bool converged = false;
};

// Stage 1 works on [theta_1, log gaps, effects, tau] so BOBYQA never leaves the model.
VectorXd to_search(const VectorXd& par, int k_thr) {
    VectorXd z = par;
    for (int j = 1; j < k_thr; ++j) z[j] = std::log(par[j] - par[j - 1]);
    return z;
}

VectorXd from_search(const VectorXd& z, int k_thr) {
    VectorXd par = z;
    for (int j = 1; j < k_thr; ++j) par[j] = par[j - 1] + std::exp(z[j]);
    return par;
}

constexpr double kTauMax = 50;  // an sd of 50 on the link scale: beyond any real spread

struct SearchContext {
    LaplaceObjective* objective;
    VectorXd z;  // the full search vector; free coordinates are set from BOBYQA
    std::vector<int> free;
    int k_thr;
    VectorXd best_modes;
    double best = kRejected;
};

double search_objective(const std::vector<double>& v, std::vector<double>&, void* data) {
    auto& c = *static_cast<SearchContext*>(data);
    for (std::size_t k = 0; k < c.free.size(); ++k) c.z[c.free[k]] = v[k];
    VectorXd u = c.best_modes;
    const double value = (*c.objective)(from_search(c.z, c.k_thr), u);
    if (value < c.best) {
        c.best = value;
        c.best_modes = u;
    }
    return value;
}

void bobyqa_search(LaplaceObjective& objective, const Problem& problem, VectorXd& par,
                   const std::vector<int>& free, VectorXd& modes) {
    SearchContext c{&objective, to_search(par, problem.thresholds()), free,
                    problem.thresholds(), modes};
    const int tau0 = problem.fixed_parameters();
    std::vector<double> v, lower, upper;
    for (int j : free) {
        v.push_back(c.z[j]);
        lower.push_back(j >= tau0 ? 0.0 : -HUGE_VAL);
        upper.push_back(j >= tau0 ? kTauMax : HUGE_VAL);
    }
    nlopt::opt optimiser(nlopt::LN_BOBYQA, unsigned(v.size()));
    optimiser.set_min_objective(search_objective, &c);
    optimiser.set_lower_bounds(lower);
    optimiser.set_upper_bounds(upper);
    optimiser.set_initial_step(0.25);
    optimiser.set_xtol_rel(1e-3);  // the Newton polish takes it from there
    optimiser.set_ftol_abs(1e-12);
    optimiser.set_maxeval(20000);
    double value = 0;
    try {
        optimiser.optimize(v, value);
    } catch (const nlopt::roundoff_limited&) {
        // BOBYQA stops at rounding level: the best point so far is what it found.
    }
    for (std::size_t k = 0; k < free.size(); ++k) c.z[free[k]] = v[k];
    par = from_search(c.z, problem.thresholds());
    VectorXd u = c.best_modes;
    if (objective(par, u) < kRejected) modes = u;
}

// Newton steps on -log L from BOBYQA's point to the maximum at rounding level: the
// Hessian (one-level differences) is computed once, the gradient (extrapolated) at each
// step; the final, extrapolated Hessian gives the standard errors.
bool newton_polish(LaplaceObjective& objective, VectorXd& par, VectorXd& modes,
                   const std::vector<int>& free, MatrixXd& hessian,
                   bool precise_hessian) {
    const VectorXd start_modes = modes;
    auto f = [&](const VectorXd& p) {
        VectorXd u = start_modes;
        return objective(p, u);
    };
    // The difference points are independent: two threads (the machines this runs on have
    // few cores; the values do not depend on which thread computes them).
    auto f_all = [&](const std::vector<VectorXd>& points) {
        std::vector<double> values(points.size());
        const bool parallel =
            std::thread::hardware_concurrency() > 1 && points.size() > 8;
        LaplaceObjective helper = objective;
        helper.evaluations = 0;
        auto run = [&](LaplaceObjective& o, std::size_t first) {
            for (std::size_t k = first; k < points.size(); k += parallel ? 2 : 1) {
                VectorXd u = start_modes;
                values[k] = o(points[k], u);
            }
        };
        if (!parallel) {
            run(objective, 0);
            return values;
        }
        std::thread other([&] { run(helper, 1); });
        run(objective, 0);
        other.join();
        objective.evaluations += helper.evaluations;
        return values;
    };
    VectorXd gradient;
    MatrixXd newton_matrix;
    finite_difference_derivatives(f_all, par, free, gradient, newton_matrix, true, false);
    Eigen::LLT<MatrixXd> chol(newton_matrix);
    bool converged = false;
    double f_par = f(par);
    for (int iteration = 0; iteration < 30 && chol.info() == Eigen::Success;
         ++iteration) {
        finite_difference_derivatives(f_all, par, free, gradient, hessian, false);
        const VectorXd step = chol.solve(gradient);
        VectorXd next = par;
        for (std::size_t k = 0; k < free.size(); ++k)
            next[free[k]] -= step[Eigen::Index(k)];
        const double f_next = f(next);
        if (!(f_next <= f_par + 1e-9 * (1 + std::abs(f_par)))) break;
        par = next;
        f_par = f_next;
        // The Newton matrix is exact to about 1e-5 (relative), so after a step below 1e-5
        // the point is within ~1e-10 of the maximum: one more gradient would only
        // confirm.
        if (max_abs(step) < 1e-5) {
            converged = true;
            break;
        }
    }
    VectorXd u = start_modes;
    objective(par, u);
    modes = u;
    if (precise_hessian)
        finite_difference_derivatives(f_all, par, free, gradient, hessian, true);
    else
        hessian = newton_matrix;
    return converged && Eigen::LLT<MatrixXd>(hessian).info() == Eigen::Success;
}

// `start_sd`: a starting sd per grouping (problem order; 1 where none is given).
LaplaceResult fit_laplace(const Problem& problem, const std::vector<int>& active,
                          const VectorXd& clm_par, const std::vector<bool>& fixed,
                          const std::vector<double>& start_sd) {
    LaplaceObjective objective(problem, active, problem.modes, problem.lagged_log_det);
    LaplaceResult r;
    r.par.resize(problem.fixed_parameters() + Eigen::Index(active.size()));
    r.par << clm_par, VectorXd::Constant(Eigen::Index(active.size()), 1.0);
    for (std::size_t k = 0; k < active.size(); ++k)
        if (std::size_t(active[k]) < start_sd.size() &&
            start_sd[std::size_t(active[k])] > 0)
            r.par[problem.fixed_parameters() + Eigen::Index(k)] =
                std::min(start_sd[std::size_t(active[k])], kTauMax / 2);
    // The objective orders its groupings (larger first): tau follows that order.
    for (int j = 0; j < int(r.par.size()); ++j)
        if (j >= problem.fixed_parameters() || !fixed[std::size_t(j)])
            r.free.push_back(j);
    r.modes = VectorXd::Zero(objective.modes());
    bobyqa_search(objective, problem, r.par, r.free, r.modes);
    for (int j = problem.fixed_parameters(); j < r.par.size(); ++j)
        r.par[j] = std::abs(r.par[j]);
    // Tau at (or next to) zero is handled by the caller as a boundary fit; the polish
    // needs an interior point.
    bool interior = true;
    for (int j = problem.fixed_parameters(); j < r.par.size(); ++j)
        interior = interior && r.par[j] > 1e-4;
    if (interior)
        r.converged = newton_polish(objective, r.par, r.modes, r.free, r.hessian,
                                    problem.precise_standard_errors);
    VectorXd u = r.modes;
    r.log_likelihood = -objective(r.par, u);
    r.evaluations = objective.evaluations;
    return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------

namespace {

struct Prepared {
    Problem problem;
    std::vector<ClmmGrouping> groupings;
    std::vector<std::string> dropped_columns;
    std::vector<std::string> notes;
};

Prepared prepare(const ClmmSpec& spec) {
    check_sizes(spec);
    Prepared prep;
    Problem& problem = prep.problem;
    problem.link = spec.link;
    problem.modes = spec.modes;
    problem.precise_standard_errors = spec.precise_standard_errors;
    problem.lagged_log_det = spec.random_intercepts.size() == 1;
    drop_unused_categories(spec, problem, prep.notes);
    const MatrixXd basis =
        keep_independent_columns(spec, problem, prep.dropped_columns, prep.notes);
    for (std::size_t g = 0; g < spec.random_intercepts.size(); ++g) {
        const Grouping grouping = used_levels(spec.random_intercepts[g]);
        ClmmGrouping out;
        out.name = grouping.name;
        out.levels = int(grouping.levels.size());
        if (grouping.levels.size() < 2) {
            out.identifiable = false;
            prep.notes.push_back("grouping " + in_quotes(grouping.name) +
                                 " has a single level: its variance is not identifiable "
                                 "(one group shows no spread between groups); fitted "
                                 "without it");
        } else if (confounded_with_fixed(spec.random_intercepts[g], basis)) {
            out.identifiable = false;
            prep.notes.push_back("grouping " + in_quotes(grouping.name) +
                                 " is confounded with the fixed effects (each of its "
                                 "levels is one fixed-effect pattern, e.g. one stimulus "
                                 "per level): its variance is not identifiable; fitted "
                                 "without it");
        } else {
            problem.groupings.push_back(grouping);
            problem.grouping_source.push_back(int(g));
        }
        prep.groupings.push_back(out);
    }
    for (const auto& g : problem.groupings)
        note_constant_raters(g, problem.y, problem.categories, prep.notes);
    return prep;
}

std::vector<ClmmEstimate> named_estimates(const std::vector<std::string>& names,
                                          const VectorXd& par, const VectorXd& se,
                                          const std::vector<bool>& infinite, int offset) {
    std::vector<ClmmEstimate> out;
    for (std::size_t k = 0; k < names.size(); ++k) {
        const auto j = Eigen::Index(offset + int(k));
        ClmmEstimate e;
        e.name = names[k];
        e.estimate = par[j];
        e.estimable = !infinite[std::size_t(j)];
        e.std_error = e.estimable && se.size() ? se[j] : 0.0;
        out.push_back(e);
    }
    return out;
}

void fill_estimates(const Problem& problem, const VectorXd& par, const VectorXd& se,
                    const std::vector<bool>& infinite, ClmmFit& fit) {
    std::vector<std::string> threshold_names;
    for (int j = 0; j < problem.thresholds(); ++j)
        threshold_names.push_back(problem.categories[std::size_t(j)] + "|" +
                                  problem.categories[std::size_t(j + 1)]);
    fit.thresholds = named_estimates(threshold_names, par, se, infinite, 0);
    fit.coefficients =
        named_estimates(problem.x_names, par, se, infinite, problem.thresholds());
    for (std::size_t j = 0; j < infinite.size(); ++j)
        if (infinite[j]) {
            const std::string name =
                int(j) < problem.thresholds()
                    ? threshold_names[j]
                    : problem.x_names[j - std::size_t(problem.thresholds())];
            fit.notes.push_back("complete separation: " + name +
                                " is not estimable (runs to infinity)");
        }
}

// The random-effects fit over `active` groupings; a variance estimated at zero is
// removed and the rest refitted (the likelihood at tau = 0 is that without the grouping).
void fit_random(const Problem& problem, std::vector<int> active, const ClmResult& clm,
                const std::vector<bool>& infinite, const std::vector<double>& start_sd,
                ClmmFit& fit) {
    while (!active.empty()) {
        active = elimination_order(problem, active);
        LaplaceResult r = fit_laplace(problem, active, clm.par, infinite, start_sd);
        fit.iterations += r.evaluations;
        auto tau_of = [&](std::size_t k) {
            return r.par[problem.fixed_parameters() + Eigen::Index(k)];
        };
        // At zero: tau next to 0, or no likelihood gained over tau = 0 (with no spread
        // between groups clmm's inner Newton takes no step and the likelihood is flat).
        LaplaceObjective objective(problem, active, problem.modes,
                                   problem.lagged_log_det);
        std::vector<int> at_zero;
        for (std::size_t k = 0; k < active.size(); ++k) {
            VectorXd without = r.par, modes;
            without[problem.fixed_parameters() + Eigen::Index(k)] = 0;
            if (tau_of(k) <= 1e-4 ||
                -objective(without, modes) >= r.log_likelihood - 1e-9)
                at_zero.push_back(active[k]);
        }
        if (!at_zero.empty()) {
            for (int g : at_zero) {
                auto& out =
                    fit.groupings[std::size_t(problem.grouping_source[std::size_t(g)])];
                out.at_boundary = true;
                fit.notes.push_back("boundary (singular) fit: the variance of " +
                                    in_quotes(out.name) + " is estimated as zero");
                active.erase(std::find(active.begin(), active.end(), g));
            }
            continue;
        }
        fit.log_likelihood = r.log_likelihood;
        fit.converged = r.converged;
        for (std::size_t k = 0; k < active.size(); ++k) {
            const double tau = tau_of(k);
            auto& out = fit.groupings[std::size_t(
                problem.grouping_source[std::size_t(active[k])])];
            out.sd = tau;
            out.variance = tau * tau;
            if (tau >= 0.99 * kTauMax)
                fit.notes.push_back("the variance of " + in_quotes(out.name) +
                                    " runs to the search limit (sd " +
                                    std::to_string(kTauMax) +
                                    "): its levels' ratings hardly overlap");
        }
        // Standard errors: invert the Hessian over the free parameters.
        const std::vector<int>& free = r.free;
        MatrixXd information = MatrixXd::Identity(r.par.size(), r.par.size());
        std::vector<bool> keep(std::size_t(r.par.size()), false);
        if (r.hessian.rows() == Eigen::Index(free.size()))
            for (std::size_t a = 0; a < free.size(); ++a) {
                keep[std::size_t(free[a])] = true;
                for (std::size_t b = 0; b < free.size(); ++b)
                    information(free[a], free[b]) =
                        r.hessian(Eigen::Index(a), Eigen::Index(b));
            }
        VectorXd se = standard_errors(information, keep);
        if (se.size() == 0 || r.hessian.rows() == 0) {
            fit.converged = false;
            fit.notes.push_back(
                "the Hessian of the Laplace likelihood is not positive definite at the "
                "optimum: standard errors are not available (reported as 0)");
            se = VectorXd::Zero(r.par.size());
        }
        std::vector<bool> infinite_all = infinite;
        infinite_all.resize(std::size_t(r.par.size()), false);
        fill_estimates(problem, r.par, se, infinite_all, fit);
        return;
    }
    // Every variance at zero: the clm fit is the fit (filled by the caller).
}

}  // namespace

namespace {

// `start`: a fit of a model with the same groupings whose sds start the search (the full
// model's, for the reduced one of a likelihood-ratio test); null: sds start at 1. Only
// the optimiser's path depends on it: it ends at the same maximum.
ClmmFit fit_clmm_from(const ClmmSpec& spec, const ClmmFit* start) {
    Prepared prep = prepare(spec);
    const Problem& problem = prep.problem;
    ClmmFit fit;
    fit.link = spec.link;
    fit.response_levels = problem.categories;
    fit.dropped_columns = prep.dropped_columns;
    fit.groupings = prep.groupings;
    fit.notes = prep.notes;
    fit.observations = problem.n();
    if (problem.categories.size() < 2) {
        fit.notes.push_back("only one rating category was used: there is nothing to fit");
        return fit;
    }
    const ClmResult clm = fit_clm_newton(problem);
    const MatrixXd information = -clm.at.hessian;
    const std::vector<bool> infinite = runs_to_infinity(problem, clm.par, information);
    fit.parameters = problem.fixed_parameters();
    for (const auto& g : fit.groupings) fit.parameters += g.identifiable ? 1 : 0;

    std::vector<int> active(problem.groupings.size());
    std::iota(active.begin(), active.end(), 0);
    fit.log_likelihood = 0;
    fit.converged = false;
    std::vector<double> start_sd;  // per identifiable grouping (problem order)
    if (start && start->groupings.size() == spec.random_intercepts.size())
        for (int source : problem.grouping_source) {
            const ClmmGrouping& g = start->groupings[std::size_t(source)];
            start_sd.push_back(g.identifiable && !g.at_boundary ? g.sd : 0.0);
        }
    if (!active.empty()) fit_random(problem, active, clm, infinite, start_sd, fit);
    if (!fit.thresholds.empty()) return fit;

    // clm: no groupings, or every variance at zero.
    fit.iterations += clm.iterations;
    fit.log_likelihood = clm.at.value;
    fit.converged = clm.converged;
    std::vector<bool> keep(infinite.size());
    for (std::size_t j = 0; j < keep.size(); ++j) keep[j] = !infinite[j];
    VectorXd se = standard_errors(information, keep);
    if (se.size() == 0) {
        fit.converged = false;
        fit.notes.push_back(
            "the Hessian of the log-likelihood is singular at the optimum: standard "
            "errors are not available (reported as 0)");
        se = VectorXd::Zero(clm.par.size());
    }
    fill_estimates(problem, clm.par, se, infinite, fit);
    return fit;
}

}  // namespace

ClmmFit fit_clmm(const ClmmSpec& spec) { return fit_clmm_from(spec, nullptr); }

double clmm_log_likelihood_at(const ClmmSpec& spec, const std::vector<double>& thresholds,
                              const std::vector<double>& coefficients,
                              const std::vector<double>& sds) {
    const Prepared prep = prepare(spec);
    const Problem& problem = prep.problem;
    if (int(thresholds.size()) != problem.thresholds() ||
        int(coefficients.size()) != problem.effects() ||
        sds.size() != problem.groupings.size())
        throw InputError("clmm: expected " + std::to_string(problem.thresholds()) +
                         " thresholds, " + std::to_string(problem.effects()) +
                         " coefficients and " + std::to_string(problem.groupings.size()) +
                         " standard deviations");
    std::vector<int> active(problem.groupings.size());
    std::iota(active.begin(), active.end(), 0);
    active = elimination_order(problem, active);
    VectorXd par(problem.fixed_parameters() + Eigen::Index(active.size()));
    for (int j = 0; j < problem.thresholds(); ++j) par[j] = thresholds[std::size_t(j)];
    for (int c = 0; c < problem.effects(); ++c)
        par[problem.thresholds() + c] = coefficients[std::size_t(c)];
    for (std::size_t k = 0; k < active.size(); ++k)
        par[problem.fixed_parameters() + Eigen::Index(k)] = sds[std::size_t(active[k])];
    double value = kRejected;
    if (active.empty()) {
        value = -clm_log_likelihood(problem, par).value;
    } else {
        LaplaceObjective objective(problem, active, problem.modes,
                                   problem.lagged_log_det);
        VectorXd modes;
        value = objective(par, modes);
    }
    if (!(value < kRejected))
        throw InputError(
            "clmm: the parameters are outside the model (thresholds not "
            "increasing, or a probability of 0)");
    return -value;
}

ClmmSpec clmm_without_term(const ClmmSpec& spec, const std::string& term) {
    const std::vector<int> columns = columns_of_term(spec.fixed, term);
    if (columns.empty()) throw InputError("clmm: no fixed term '" + term + "'");
    ClmmSpec reduced = spec;
    reduced.precise_standard_errors = false;  // the test needs only its log-likelihood
    std::vector<int> keep;
    for (int c = 0; c < int(spec.fixed.x.cols()); ++c)
        if (std::find(columns.begin(), columns.end(), c) == columns.end())
            keep.push_back(c);
    reduced.fixed.x.resize(spec.fixed.x.rows(), Eigen::Index(keep.size()));
    reduced.fixed.names.clear();
    reduced.fixed.term_of_column.clear();
    for (std::size_t k = 0; k < keep.size(); ++k) {
        reduced.fixed.x.col(Eigen::Index(k)) = spec.fixed.x.col(keep[k]);
        reduced.fixed.names.push_back(spec.fixed.names[std::size_t(keep[k])]);
        reduced.fixed.term_of_column.push_back(
            spec.fixed.term_of_column[std::size_t(keep[k])]);
    }
    return reduced;
}

ClmmLikelihoodRatioTest clmm_likelihood_ratio_test(const ClmmSpec& spec,
                                                   const ClmmFit& full,
                                                   const std::string& term) {
    const ClmmFit without = fit_clmm_from(clmm_without_term(spec, term), &full);
    return clmm_likelihood_ratio_test(full, without, term);
}

ClmmLikelihoodRatioTest clmm_likelihood_ratio_test(const ClmmFit& full,
                                                   const ClmmFit& without,
                                                   const std::string& term) {
    ClmmLikelihoodRatioTest test;
    test.term = term;
    test.log_likelihood_full = full.log_likelihood;
    test.parameters_full = full.parameters;
    test.log_likelihood_reduced = without.log_likelihood;
    test.parameters_reduced = without.parameters;
    test.df = full.parameters - without.parameters;
    test.chi_square = std::max(0.0, 2 * (full.log_likelihood - without.log_likelihood));
    for (const auto& note : full.notes) test.notes.push_back("full model: " + note);
    for (const auto& note : without.notes)
        test.notes.push_back("without " + term + ": " + note);
    if (test.df <= 0) {
        test.p = 1;
        test.notes.push_back("the term " + in_quotes(term) +
                             " adds no estimable parameter (its columns were dropped): "
                             "there is nothing to test");
        return test;
    }
    boost::math::chi_squared_distribution<double> chi(test.df);
    test.p = boost::math::cdf(boost::math::complement(chi, test.chi_square));
    return test;
}

}  // namespace lucent::analysis::mixed
