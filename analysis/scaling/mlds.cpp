#include "analysis/scaling/mlds.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <nlopt.hpp>
#include <random>

#include "analysis/data/long_table.h"
#include "analysis/report/format.h"
#include "analysis/scaling/binomial_glm.h"
#include "analysis/scaling/paired_comparison.h"

namespace lucent::analysis {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

std::optional<double> finite(double v) {
    return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::string short_text(double v) { return format_short(Statistic(v)); }

// The GLM's design: one row per trial, columns psi_2..psi_p.
BinomialData design(const MldsData& data) {
    const auto n = static_cast<Eigen::Index>(data.trials.size());
    const auto k = static_cast<Eigen::Index>(data.stimuli.size()) - 1;
    BinomialData glm;
    glm.x = Eigen::MatrixXd::Zero(n, k);
    glm.successes.resize(n);
    glm.trials = Eigen::VectorXd::Ones(n);
    for (Eigen::Index r = 0; r < n; ++r) {
        const MldsTrial& t = data.trials[static_cast<std::size_t>(r)];
        const std::array<double, 4> sign{1.0, -1.0, -1.0, 1.0};
        for (int j = 0; j < 4; ++j)
            if (t.q[j] > 0) glm.x(r, static_cast<Eigen::Index>(t.q[j]) - 1) += sign[j];
        glm.successes[r] = t.second_larger ? 1.0 : 0.0;
    }
    return glm;
}

// A deterministic uniform in (0, 1) from the seeded engine (the same on every library).
double uniform(std::mt19937_64& rng) {
    return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
}

// The six-point sets of the data: for each, the trials of its quadruples A = (a1,a2;
// b1,b2), B = (a2,a3; b2,b3), E = (a1,a3; b1,b3), as MLDS's Get6pts finds them (only
// quadruples shown in that exact order of pairs).
struct SixPointSet {
    std::array<std::vector<std::size_t>, 3> trials;
};
std::vector<SixPointSet> six_point_sets(const MldsData& data) {
    std::map<std::array<std::size_t, 4>, std::vector<std::size_t>> shown;
    for (std::size_t i = 0; i < data.trials.size(); ++i) {
        const auto& q = data.trials[i].q;
        if (q[0] < q[1] && q[1] != q[2] && q[2] < q[3]) shown[q].push_back(i);
    }
    std::vector<SixPointSet> sets;
    const std::size_t p = data.stimuli.size();
    auto find = [&](std::size_t a, std::size_t b, std::size_t c,
                    std::size_t d) -> const std::vector<std::size_t>* {
        const auto it = shown.find({a, b, c, d});
        return it == shown.end() ? nullptr : &it->second;
    };
    for (std::size_t a1 = 0; a1 < p; ++a1)
        for (std::size_t a2 = a1 + 1; a2 < p; ++a2)
            for (std::size_t a3 = a2 + 1; a3 < p; ++a3)
                for (std::size_t b1 = std::max<std::size_t>(1, a1 + 1); b1 < p; ++b1)
                    for (std::size_t b2 = b1 + 1; b2 < p; ++b2)
                        for (std::size_t b3 = b2 + 1; b3 < p; ++b3) {
                            const auto* A = find(a1, a2, b1, b2);
                            const auto* B = find(a2, a3, b2, b3);
                            const auto* E = find(a1, a3, b1, b3);
                            if (A && B && E) sets.push_back({{*A, *B, *E}});
                        }
    return sets;
}

double six_point_log_likelihood(const std::vector<SixPointSet>& sets,
                                const std::vector<char>& response,
                                const Eigen::VectorXd& fitted) {
    double sum = 0.0;
    for (const SixPointSet& set : sets)
        for (const auto& trials : set.trials)
            for (std::size_t i : trials) {
                const double p =
                    std::clamp(fitted[static_cast<Eigen::Index>(i)], kEps, 1 - kEps);
                sum += response[i] ? std::log(p) : std::log1p(-p);
            }
    return sum;
}

// The percentile of sorted values (R's quantile type 7).
double percentile(const std::vector<double>& sorted, double q) {
    const double h = (static_cast<double>(sorted.size()) - 1.0) * q;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
    return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

// Direct maximum likelihood in MLDS's normalisation (psi_1 = 0, psi_p = 1): the free
// values psi_2..psi_{p-1} and log sigma, by L-BFGS on the analytic gradient, started
// from equal steps (so the agreement with the GLM is not built in).
MldsDirectFit direct_fit(const MldsData& data) {
    const std::size_t p = data.stimuli.size();
    const std::size_t free = p - 2;
    struct Context {
        const MldsData* data;
        std::size_t p;
    } context{&data, p};
    auto objective = [](const std::vector<double>& x, std::vector<double>& grad,
                        void* raw) -> double {
        const Context& c = *static_cast<const Context*>(raw);
        std::vector<double> psi(c.p, 0.0);
        for (std::size_t j = 1; j + 1 < c.p; ++j) psi[j] = x[j - 1];
        psi[c.p - 1] = 1.0;
        const double sigma = std::exp(x.back());
        if (!grad.empty()) std::fill(grad.begin(), grad.end(), 0.0);
        double negative = 0.0;
        const std::array<double, 4> sign{1.0, -1.0, -1.0, 1.0};
        for (const MldsTrial& t : c.data->trials) {
            double d = 0.0;
            for (int j = 0; j < 4; ++j) d += sign[j] * psi[t.q[j]];
            const double z = d / sigma;
            // log Phi(+-z) and its derivative, stable in the tails (Mills ratio).
            const double s = t.second_larger ? z : -z;
            const double cdf = 0.5 * std::erfc(-s / std::sqrt(2.0));
            const double pdf = std::exp(-0.5 * s * s) / std::sqrt(2.0 * M_PI);
            const double log_cdf =
                cdf > 1e-300 ? std::log(cdf)
                             : -0.5 * s * s - std::log(-s) - 0.5 * std::log(2.0 * M_PI);
            negative -= log_cdf;
            if (grad.empty()) continue;
            const double ratio = cdf > 1e-300 ? pdf / cdf : -s;     // d log Phi(s) / ds
            const double dz = -(t.second_larger ? ratio : -ratio);  // d(-logL)/dz
            for (int j = 0; j < 4; ++j)
                if (t.q[j] > 0 && t.q[j] + 1 < c.p)
                    grad[t.q[j] - 1] += dz * sign[j] / sigma;
            grad.back() += dz * -z;
        }
        return negative;
    };
    std::vector<double> x(free + 1);
    for (std::size_t j = 0; j < free; ++j)
        x[j] = static_cast<double>(j + 1) / static_cast<double>(p - 1);
    x.back() = std::log(0.2);
    nlopt::opt optimiser(nlopt::LD_LBFGS, static_cast<unsigned>(x.size()));
    optimiser.set_min_objective(objective, &context);
    optimiser.set_ftol_rel(1e-15);
    optimiser.set_xtol_rel(1e-12);
    optimiser.set_maxeval(20000);
    MldsDirectFit fit;
    double value = 0.0;
    try {
        const nlopt::result r = optimiser.optimize(x, value);
        fit.converged = r > 0;
    } catch (const nlopt::roundoff_limited&) {
        fit.converged = true;  // at the optimum to rounding
        value = optimiser.last_optimum_value();
    } catch (const std::exception&) {
        fit.converged = false;
    }
    fit.scale.assign(p, 0.0);
    for (std::size_t j = 0; j < free; ++j) fit.scale[j + 1] = x[j];
    fit.scale[p - 1] = 1.0;
    fit.sigma = std::exp(x.back());
    fit.log_likelihood = -value;
    return fit;
}

}  // namespace

MldsFit fit_mlds(const MldsData& data, const MldsOptions& options) {
    MldsFit fit;
    fit.stimuli = data.stimuli;
    const std::size_t p = data.stimuli.size();
    fit.trials = static_cast<int>(data.trials.size());
    fit.glm_scale.assign(p, std::nullopt);
    fit.glm_se = fit.scale = fit.se = fit.ci_low = fit.ci_high = fit.glm_scale;
    if (p < 3) {
        fit.notes.push_back(
            "A difference scale needs at least 3 stimuli; this series has " +
            std::to_string(p) + ".");
        return fit;
    }
    for (const MldsTrial& t : data.trials)
        for (std::size_t i : t.q)
            if (i >= p)
                throw InputError("MLDS: a trial names stimulus index " +
                                 std::to_string(i) + " of only " + std::to_string(p));
    if (data.trials.empty()) {
        fit.notes.push_back("No triad or quadruple judgements to scale.");
        return fit;
    }
    const BinomialData glm = design(data);
    const BinomialFit g = fit_binomial_glm(glm, BinomialLink::probit, 1e-14, 200);
    fit.converged = g.converged && !g.separation && !g.rank_deficient;
    fit.df_residual = g.df_residual;
    fit.deviance = finite(g.deviance);
    fit.null_deviance = finite(g.null_deviance);
    fit.aic = finite(g.aic);
    fit.log_likelihood = finite(g.log_likelihood);
    if (fit.deviance && fit.null_deviance && *fit.null_deviance > 0)
        fit.daf = (*fit.null_deviance - *fit.deviance) / *fit.null_deviance;
    if (g.rank_deficient) {
        fit.notes.push_back(
            "The judgements do not identify every scale value (some "
            "stimulus never differs from another in any trial's design); "
            "no scale is reported.");
        return fit;
    }
    fit.glm_scale[0] = 0.0;
    fit.glm_se[0] = 0.0;
    const auto k = static_cast<Eigen::Index>(p - 1);
    for (Eigen::Index j = 0; j < k; ++j) {
        fit.glm_scale[static_cast<std::size_t>(j) + 1] = finite(g.coefficients[j]);
        fit.glm_se[static_cast<std::size_t>(j) + 1] = finite(g.standard_errors[j]);
    }
    const double top = g.coefficients[k - 1];
    if (g.separation) {
        fit.notes.push_back(
            "The judgements are perfectly consistent with a scale (no judgement goes "
            "against the others): the decision noise sigma is 0 and the scale values in "
            "its units run to infinity; only the order of the stimuli is known.");
        for (auto* v : {&fit.glm_scale, &fit.glm_se})
            for (std::size_t j = 1; j < p; ++j) (*v)[j].reset();
        return fit;
    }
    if (!(top > 0)) {
        fit.notes.push_back(
            "The last stimulus's scale value is not above the first's (psi_" +
            std::to_string(p) + " = " + short_text(top) +
            "): the judgements show no growth along the series, so the scale cannot be "
            "normalised to psi_" +
            std::to_string(p) + " = 1.");
    } else {
        const Eigen::MatrixXd& v = g.covariance;
        fit.scale[0] = 0.0;
        fit.se[0] = 0.0;
        for (Eigen::Index j = 0; j < k; ++j) {
            const double s = g.coefficients[j] / top;
            const double var =
                (v(j, j) - 2.0 * s * v(j, k - 1) + s * s * v(k - 1, k - 1)) / (top * top);
            fit.scale[static_cast<std::size_t>(j) + 1] = finite(s);
            fit.se[static_cast<std::size_t>(j) + 1] =
                finite(std::sqrt(std::max(0.0, var)));
        }
        fit.sigma = finite(1.0 / top);
        fit.sigma_se = finite(std::sqrt(std::max(0.0, v(k - 1, k - 1))) / (top * top));
    }
    if (options.direct && p >= 3 && top > 0) fit.direct = direct_fit(data);

    // Simulations from the fitted probabilities: the six-point test and the bootstrap.
    std::vector<char> observed(data.trials.size());
    for (std::size_t i = 0; i < data.trials.size(); ++i)
        observed[i] = data.trials[i].second_larger;
    const std::vector<SixPointSet> sets = six_point_sets(data);
    fit.six_point.sets = static_cast<int>(sets.size());
    for (const SixPointSet& set : sets) {
        std::array<double, 3> share{};
        for (int j = 0; j < 3; ++j) {
            for (std::size_t i : set.trials[j]) share[j] += observed[i];
            share[j] /= static_cast<double>(set.trials[j].size());
        }
        if ((share[0] > 0.5 && share[1] > 0.5 && share[2] < 0.5) ||
            (share[0] < 0.5 && share[1] < 0.5 && share[2] > 0.5))
            ++fit.six_point.violations;
    }
    if (!sets.empty())
        fit.six_point.log_likelihood = six_point_log_likelihood(sets, observed, g.fitted);

    std::mt19937_64 rng(options.seed);
    auto simulate = [&](BinomialData& sim, std::vector<char>& response) {
        for (Eigen::Index r = 0; r < g.fitted.size(); ++r) {
            response[static_cast<std::size_t>(r)] = uniform(rng) < g.fitted[r];
            sim.successes[r] = response[static_cast<std::size_t>(r)];
        }
        return fit_binomial_glm(sim, BinomialLink::probit, 1e-10, 100);
    };
    if (options.six_point_simulations > 0 && fit.six_point.log_likelihood) {
        BinomialData sim = glm;
        std::vector<char> response(observed.size());
        int at_or_below = 0;
        for (int s = 0; s < options.six_point_simulations; ++s) {
            const BinomialFit refit = simulate(sim, response);
            if (six_point_log_likelihood(sets, response, refit.fitted) <=
                *fit.six_point.log_likelihood)
                ++at_or_below;
        }
        fit.six_point.simulations = options.six_point_simulations;
        fit.six_point.p =
            static_cast<double>(at_or_below) / options.six_point_simulations;
        if (*fit.six_point.p < 0.05)
            fit.notes.push_back(
                "The six-point test rejects the model (p = " +
                format_p_short(fit.six_point.p) + ", " +
                std::to_string(fit.six_point.violations) + " of " +
                std::to_string(fit.six_point.sets) +
                " six-point sets violated): the judgements are not those of one "
                "difference scale with constant noise.");
    } else if (options.six_point_simulations > 0) {
        fit.notes.push_back(
            "The six-point test needs quadruples (a,b;c,d) whose six-point "
            "sets were all shown; these data have none.");
    }
    if (options.bootstrap > 0 && fit.sigma) {
        BinomialData sim = glm;
        std::vector<char> response(observed.size());
        std::vector<std::vector<double>> samples(p);  // scale 1..p-2 and sigma (slot 0)
        for (int b = 0; b < options.bootstrap; ++b) {
            const BinomialFit refit = simulate(sim, response);
            const double last = refit.coefficients[k - 1];
            if (!(last > 0) || !refit.coefficients.allFinite() || refit.rank_deficient)
                continue;
            ++fit.bootstrap_samples;
            for (Eigen::Index j = 0; j + 1 < k; ++j)
                samples[static_cast<std::size_t>(j) + 1].push_back(refit.coefficients[j] /
                                                                   last);
            samples[0].push_back(1.0 / last);
        }
        if (fit.bootstrap_samples >= 2) {
            const double tail = (1.0 - options.level) / 2.0;
            for (auto& s : samples) std::sort(s.begin(), s.end());
            for (std::size_t j = 1; j + 1 < p; ++j) {
                fit.ci_low[j] = finite(percentile(samples[j], tail));
                fit.ci_high[j] = finite(percentile(samples[j], 1.0 - tail));
            }
            fit.ci_low[0] = fit.ci_high[0] = 0.0;
            fit.ci_low[p - 1] = fit.ci_high[p - 1] = 1.0;
            fit.sigma_ci_low = finite(percentile(samples[0], tail));
            fit.sigma_ci_high = finite(percentile(samples[0], 1.0 - tail));
        }
        if (fit.bootstrap_samples < options.bootstrap)
            fit.notes.push_back(
                std::to_string(options.bootstrap - fit.bootstrap_samples) + " of " +
                std::to_string(options.bootstrap) +
                " bootstrap samples showed no growth along the series "
                "(psi_p <= 0) and were left out of the intervals.");
    }
    if (fit.daf && *fit.daf < 0.1)
        fit.notes.push_back("The scale accounts for " + short_text(100.0 * *fit.daf) +
                            "% of the deviance: the judgements are close to chance.");
    return fit;
}

MldsData mlds_data(const std::vector<const ChoiceRow*>& rows,
                   const std::vector<std::string>& stimuli) {
    MldsData data;
    data.stimuli = stimuli;
    std::map<std::string, std::size_t> index;
    for (std::size_t s = 0; s < stimuli.size(); ++s) index[stimuli[s]] = s;
    for (const ChoiceRow* row : rows) {
        if (row->task == ChoiceTask::pair || row->is_catch) continue;
        std::array<std::size_t, 4> shown{};
        const int n = shown_count(row->task);
        bool known = true;
        for (int j = 0; j < n; ++j) {
            const auto it = index.find(row->shown[j]);
            if (it == index.end())
                known = false;
            else
                shown[j] = it->second;
        }
        if (!known) continue;
        std::array<std::size_t, 2> first{shown[0], shown[1]},
            second = n == 3 ? std::array<std::size_t, 2>{shown[1], shown[2]}
                            : std::array<std::size_t, 2>{shown[2], shown[3]};
        std::sort(first.begin(), first.end());
        std::sort(second.begin(), second.end());
        bool second_larger = row->choice == 2;
        if (second < first) {  // the series' first pair was shown second
            std::swap(first, second);
            second_larger = !second_larger;
        }
        if (first == second) continue;  // the same pair twice: no information
        data.trials.push_back(
            {{first[0], first[1], second[0], second[1]}, second_larger});
    }
    return data;
}

std::vector<MldsBlockFits> fit_mlds_blocks(
    const ChoiceTable& table, const MldsOptions& options,
    const std::map<std::string, std::vector<std::string>>& orders) {
    std::vector<MldsBlockFits> result;
    for (const ChoiceBlock& b : choice_blocks(table, false, orders)) {
        MldsBlockFits block;
        block.block = b.block;
        block.question = b.question;
        block.stimuli = b.stimuli;
        block.values = b.values;
        block.catch_trials = b.catch_trials;
        block.catch_failed = b.catch_failed;
        block.pooled = fit_mlds(mlds_data(b.rows, b.stimuli), options);
        for (const auto& [who, rows] : b.participants)
            block.participants.emplace_back(
                who, fit_mlds(mlds_data(rows, b.stimuli), options));
        result.push_back(std::move(block));
    }
    return result;
}

}  // namespace lucent::analysis
