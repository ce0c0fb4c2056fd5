#include "analysis/psychometric/psychometric.h"

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <nlopt.hpp>
#include <random>

#include "analysis/data/long_table.h"
#include "analysis/report/format.h"

namespace lucent::analysis {
namespace {

constexpr double kTiny = 1e-300;

std::string short_text(double v) { return format_short(Statistic(v)); }

// Both families as a location-scale family on u (x for the Gaussian, log x for the
// Weibull): z = (u - m) / s, F = G(z) with G the standard normal or the Gumbel (minimum)
// distribution 1 - exp(-e^z). Gaussian: m = alpha, s = beta; Weibull: m = log alpha,
// s = 1 / beta. The search runs on (m, log s[, lambda]).
bool gaussian(PsychometricFamily family) {
    return family == PsychometricFamily::cumulative_gaussian;
}
double g_cdf(bool gauss, double z) {
    return gauss ? 0.5 * std::erfc(-z / std::sqrt(2.0)) : -std::expm1(-std::exp(z));
}
double g_ccdf(bool gauss, double z) {
    return gauss ? 0.5 * std::erfc(z / std::sqrt(2.0)) : std::exp(-std::exp(z));
}
double g_pdf(bool gauss, double z) {
    return gauss ? std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI)
                 : std::exp(z - std::exp(z));
}
double g_quantile(bool gauss, double p) {
    return gauss ? boost::math::quantile(boost::math::normal(), p)
                 : std::log(-std::log1p(-p));
}
double to_u(bool gauss, double x) { return gauss ? x : std::log(x); }

struct Problem {
    bool gauss = true;
    double guess = 0.5;
    bool free_lapse = true;
    double lapse = 0.0;
    std::vector<double> u, k, n;
};

// Negative log-likelihood without the binomial coefficients, and its gradient.
double negative_log_likelihood(const Problem& p, const double* theta, double* grad) {
    const double m = theta[0], s = std::exp(theta[1]);
    const double lapse = p.free_lapse ? theta[2] : p.lapse;
    const double range = 1.0 - p.guess - lapse;
    double value = 0.0;
    double g0 = 0.0, g1 = 0.0, g2 = 0.0;
    for (std::size_t i = 0; i < p.u.size(); ++i) {
        const double z = (p.u[i] - m) / s;
        const double psi = std::max(p.guess + range * g_cdf(p.gauss, z), kTiny);
        const double q = std::max(lapse + range * g_ccdf(p.gauss, z), kTiny);
        const double wrong = p.n[i] - p.k[i];
        if (p.k[i] > 0) value -= p.k[i] * std::log(psi);
        if (wrong > 0) value -= wrong * std::log(q);
        if (grad == nullptr) continue;
        // d(-logL)/dpsi, then the chain rule through z.
        const double d =
            -(p.k[i] > 0 ? p.k[i] / psi : 0.0) + (wrong > 0 ? wrong / q : 0.0);
        const double dens = range * g_pdf(p.gauss, z);
        g0 += d * dens * (-1.0 / s);
        g1 += d * dens * (-z);
        g2 += d * (-g_cdf(p.gauss, z));
    }
    if (grad != nullptr) {
        grad[0] = g0;
        grad[1] = g1;
        if (p.free_lapse) grad[2] = g2;
    }
    return value;
}

struct Search {
    std::vector<double> theta;
    double value = std::numeric_limits<double>::infinity();
    bool converged = false;
};

struct Bounds {
    std::vector<double> lower, upper;
};

Search minimise(const Problem& p, const Bounds& b, std::vector<double> start) {
    auto objective = [](const std::vector<double>& x, std::vector<double>& grad,
                        void* raw) -> double {
        return negative_log_likelihood(*static_cast<const Problem*>(raw), x.data(),
                                       grad.empty() ? nullptr : grad.data());
    };
    Search best;
    for (int pass = 0; pass < 2; ++pass) {
        nlopt::opt optimiser(nlopt::LD_LBFGS, static_cast<unsigned>(start.size()));
        optimiser.set_min_objective(objective, const_cast<Problem*>(&p));
        optimiser.set_lower_bounds(b.lower);
        optimiser.set_upper_bounds(b.upper);
        optimiser.set_ftol_rel(1e-15);
        optimiser.set_xtol_rel(1e-13);
        optimiser.set_maxeval(4000);
        for (std::size_t j = 0; j < start.size(); ++j)
            start[j] = std::clamp(start[j], b.lower[j], b.upper[j]);
        double value = 0.0;
        bool converged = false;
        try {
            converged = optimiser.optimize(start, value) > 0;
        } catch (const nlopt::roundoff_limited&) {
            converged = true;  // at the optimum to rounding
            value = optimiser.last_optimum_value();
        } catch (const std::exception&) {
            value = negative_log_likelihood(p, start.data(), nullptr);
        }
        if (!std::isfinite(value)) break;
        if (value <= best.value) best = {start, value, converged};
    }
    return best;
}

// One end of a bootstrap interval: the percentile (R's quantile type 7) of the resamples
// where `below` of them lie below the tested range and `above` above it, only their side
// known, `inside` (sorted) holding the others' values. A percentile that reaches an
// outside resample is withheld: only its side is known (below_range or above_range).
struct End {
    ThresholdStatus status = ThresholdStatus::not_identified;
    std::optional<double> value;
};

End percentile_end(const std::vector<double>& inside, std::size_t below,
                   std::size_t above, double q) {
    const std::size_t n = inside.size() + below + above;
    if (n == 0) return {};
    const double h = (static_cast<double>(n) - 1.0) * q;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, n - 1);
    const double frac = h - static_cast<double>(lo);
    const auto side = [&](std::size_t i) {
        return i < below ? -1 : (i >= below + inside.size() ? 1 : 0);
    };
    if (side(lo) < 0) return {ThresholdStatus::below_range, std::nullopt};
    if (side(lo) > 0 || (frac > 0.0 && side(hi) > 0))
        return {ThresholdStatus::above_range, std::nullopt};
    const double a = inside[lo - below];
    const double b = side(hi) == 0 ? inside[hi - below] : a;
    return {ThresholdStatus::estimated, a + frac * (b - a)};
}

double uniform(std::mt19937_64& rng) {
    return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
}

double log_choose(double n, double k) {
    return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0);
}

std::optional<double> finite(double v) {
    return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

void check_options(const PsychometricOptions& o) {
    auto bad = [](const std::string& what) {
        throw InputError("psychometric function: " + what);
    };
    if (!(o.guess >= 0.0 && o.guess < 1.0))
        bad("the guess rate " + short_text(o.guess) + " is not in [0, 1)");
    if (!(o.max_lapse >= 0.0 && o.max_lapse < 1.0 - o.guess))
        bad("the largest lapse rate " + short_text(o.max_lapse) + " is not in [0, " +
            short_text(1.0 - o.guess) + ")");
    if (!o.free_lapse && !(o.lapse >= 0.0 && o.lapse < 1.0 - o.guess))
        bad("the lapse rate " + short_text(o.lapse) + " is not in [0, " +
            short_text(1.0 - o.guess) + ")");
    if (!(o.threshold_level > 0.0 && o.threshold_level < 1.0))
        bad("the threshold level " + short_text(o.threshold_level) + " is not in (0, 1)");
    if (o.p_correct_level && !(*o.p_correct_level > o.guess && *o.p_correct_level < 1.0))
        bad("the proportion correct " + short_text(*o.p_correct_level) +
            " of the threshold is not between the guess rate " + short_text(o.guess) +
            " and 1");
    if (o.bootstrap < 0)
        bad("the bootstrap count " + std::to_string(o.bootstrap) + " < 0");
    if (!(o.level > 0.0 && o.level < 1.0))
        bad("the interval level " + short_text(o.level) + " is not in (0, 1)");
    if (!(o.test_level > 0.0 && o.test_level < 1.0))
        bad("the test level " + short_text(o.test_level) + " is not in (0, 1)");
}

Threshold bounded(ThresholdStatus status, double bound) {
    Threshold t;
    t.status = status;
    t.bound = bound;
    t.text = (status == ThresholdStatus::below_range ? "< " : "> ") + short_text(bound);
    return t;
}

Threshold not_identified() {
    Threshold t;
    t.text = "not identified";
    return t;
}

// The fitted state on the search's scale.
struct State {
    double m = 0, s = 1, lapse = 0;
};

// u at F = level, and dpsi/dx there.
std::pair<double, double> threshold_at(const Problem& p, const State& st,
                                       double f_level) {
    const double z = g_quantile(p.gauss, f_level);
    const double u = st.m + st.s * z;
    const double range = 1.0 - p.guess - st.lapse;
    const double x = p.gauss ? u : std::exp(u);
    const double slope =
        p.gauss ? range * g_pdf(true, z) / st.s : range * g_pdf(false, z) / (st.s * x);
    return {x, slope};
}

// A bootstrap resample's threshold and slope, as the point estimate's rules classify
// them.
enum class SlopeKind { identified, steep, unknown };
struct Resample {
    double x = 0.0, slope = 0.0;
    int side = 0;  // -1 below the tested range, +1 above, 0 within
    SlopeKind kind = SlopeKind::identified;
};

// Stage 5: a threshold's percentile interval from its bootstrap resamples, with the
// slope's; an end that the resamples put outside the tested range [x_min, x_max] is
// said as "< x_min" or "> x_max" with a note, not given a number.
void bootstrap_interval(Threshold& t, const std::vector<Resample>& v,
                        const std::string& name, const PsychometricOptions& options,
                        double x_min, double x_max, std::vector<std::string>& notes) {
    const double lo = (1.0 - options.level) / 2.0, hi = 1.0 - lo;
    const std::string level_text = short_text(100.0 * options.level) + "%";
    if (t.status != ThresholdStatus::estimated) return;
    std::vector<double> inside, slopes;
    std::size_t below = 0, above = 0, steep = 0, unknown = 0;
    for (const Resample& r : v) {
        if (r.side < 0) ++below;
        if (r.side > 0) ++above;
        if (r.side == 0) inside.push_back(r.x);
        if (r.kind == SlopeKind::steep) ++steep;
        if (r.kind == SlopeKind::unknown) ++unknown;
        if (r.kind == SlopeKind::identified) slopes.push_back(r.slope);
    }
    std::sort(inside.begin(), inside.end());
    std::sort(slopes.begin(), slopes.end());
    t.bootstrap_below = static_cast<int>(below);
    t.bootstrap_above = static_cast<int>(above);
    const End low_end = percentile_end(inside, below, above, lo);
    const End high_end = percentile_end(inside, below, above, hi);
    t.ci_low_status = low_end.status;
    t.ci_low = low_end.value;
    t.ci_high_status = high_end.status;
    t.ci_high = high_end.value;
    const auto end_text = [&](const End& e) {
        if (e.status == ThresholdStatus::below_range) return "< " + short_text(x_min);
        if (e.status == ThresholdStatus::above_range) return "> " + short_text(x_max);
        return short_text(*e.value);
    };
    t.ci_text = end_text(low_end) + " .. " + end_text(high_end);
    const std::string of =
        "Of the " + std::to_string(v.size()) + " bootstrap resamples, ";
    const auto share = [&](std::size_t k) {
        return std::to_string(k) + " (" +
               short_text(100.0 * static_cast<double>(k) / v.size()) + "%)";
    };
    const std::string leaves = "more than the " + short_text(100.0 * lo) + "% that the " +
                               level_text + " interval leaves out on that side";
    if (below > 0 && (low_end.status == ThresholdStatus::below_range ||
                      high_end.status == ThresholdStatus::below_range))
        notes.push_back(of + share(below) + " put the " + name +
                        " below the smallest intensity tested, " + short_text(x_min) +
                        ": " + leaves +
                        ", so the interval's lower end is only said to be "
                        "below " +
                        short_text(x_min) + " (" + t.ci_text + ").");
    if (above > 0 && (high_end.status == ThresholdStatus::above_range ||
                      low_end.status == ThresholdStatus::above_range))
        notes.push_back(of + share(above) + " put the " + name +
                        " above the largest intensity tested, " + short_text(x_max) +
                        ": " + leaves +
                        ", so the interval's upper end is only said to be "
                        "above " +
                        short_text(x_max) + " (" + t.ci_text + ").");
    if (!t.slope) return;
    // Unknown slopes on the far side of each end, steep ones above.
    const End slope_low = percentile_end(slopes, unknown, steep, lo);
    const End slope_high = percentile_end(slopes, 0, unknown + steep, hi);
    if (slope_low.status == ThresholdStatus::estimated) t.slope_ci_low = slope_low.value;
    if (slope_high.status == ThresholdStatus::estimated)
        t.slope_ci_high = slope_high.value;
    if (!t.slope_ci_low || !t.slope_ci_high)
        notes.push_back(of + share(steep + unknown) +
                        " have no identified slope at the " + name + " (" +
                        std::to_string(steep) + " jump between two intensities, " +
                        std::to_string(unknown) + " put the " + name +
                        " outside the tested range or rise nowhere "
                        "on it): " +
                        leaves + ", so the slope's interval has no " +
                        (!t.slope_ci_low && !t.slope_ci_high
                             ? std::string("ends")
                             : std::string(t.slope_ci_low ? "upper end" : "lower end")) +
                        ".");
}

// Stage 1: the bins with trials, checked (finite intensities, 0 <= correct <= trials,
// positive intensities for the Weibull) and sorted by intensity.
std::vector<PsychometricBin> checked_bins(const std::vector<PsychometricBin>& input,
                                          bool gauss) {
    std::vector<PsychometricBin> bins;
    for (std::size_t i = 0; i < input.size(); ++i) {
        const PsychometricBin& b = input[i];
        const std::string where = "psychometric function: bin " + std::to_string(i + 1);
        if (!std::isfinite(b.x)) throw InputError(where + " has no finite intensity");
        if (b.n_trials < 0 || b.n_correct < 0 || b.n_correct > b.n_trials)
            throw InputError(where + " has " + std::to_string(b.n_correct) +
                             " correct of " + std::to_string(b.n_trials) + " trials");
        if (!gauss && b.x <= 0.0)
            throw InputError(
                where +
                ": the Weibull needs positive intensities, not x = " + short_text(b.x));
        if (b.n_trials > 0) bins.push_back(b);
    }
    std::stable_sort(
        bins.begin(), bins.end(),
        [](const PsychometricBin& a, const PsychometricBin& b) { return a.x < b.x; });
    return bins;
}

// The tested range and the proportion correct of a fit with trials, and the tally its
// notes quote ("K of N trials correct").
struct Summary {
    double x_min = 0, x_max = 0, proportion = 0;
    std::string tally;
};

Summary summary_of(const PsychometricFit& fit) {
    return {fit.bins.front().x, fit.bins.back().x,
            static_cast<double>(fit.correct) / fit.trials,
            std::to_string(fit.correct) + " of " + std::to_string(fit.trials) +
                " trials correct"};
}

// Stage 2: the data that settle the answer without a fit (all or none correct, below
// chance, one intensity), said in fit.notes; true when one did.
bool settled_without_a_fit(PsychometricFit& fit, const Summary& summary,
                           const PsychometricOptions& options) {
    auto both = [&](const Threshold& t) {
        fit.threshold = t;
        if (options.p_correct_level) fit.threshold_p = t;
    };
    const double x_min = summary.x_min, x_max = summary.x_max;
    const double proportion = summary.proportion;
    const std::string& tally = summary.tally;
    if (fit.correct == fit.trials) {
        both(bounded(ThresholdStatus::below_range, x_min));
        fit.notes.push_back("Every response was correct (" + tally +
                            "): the threshold is below the smallest intensity tested, " +
                            short_text(x_min) + "; the slope is not identified.");
        return true;
    }
    if (fit.correct == 0 && options.guess == 0.0) {
        both(bounded(ThresholdStatus::above_range, x_max));
        fit.notes.push_back("No response was correct (" + tally +
                            "): the threshold is above the largest intensity tested, " +
                            short_text(x_max) + "; the slope is not identified.");
        return true;
    }
    if (options.guess > 0.0) {
        const boost::math::binomial_distribution<> chance(fit.trials, options.guess);
        const double p_below = boost::math::cdf(chance, fit.correct);
        if (p_below < options.test_level) {
            fit.notes.push_back(
                "Below chance: " + tally + " (" + short_text(100.0 * proportion) +
                "%) against a guess rate of " + short_text(100.0 * options.guess) +
                "% (binomial test p = " + format_p_short(p_below) +
                "); no threshold (are the responses inverted?).");
            return true;
        }
    }
    if (x_min == x_max) {
        fit.notes.push_back("One intensity only (x = " + short_text(x_min) + ", " +
                            tally + "): the threshold and the slope are not identified.");
        return true;
    }
    return false;
}

// Stage 3: the maximum-likelihood fit from nine starts, within bounds that let the
// steepest function jump between the two closest intensities.
struct LikelihoodFit {
    Problem problem;
    Bounds bounds;
    Search best;
};

LikelihoodFit maximum_likelihood(const std::vector<PsychometricBin>& bins,
                                 const PsychometricOptions& options, bool gauss) {
    LikelihoodFit out;
    Problem& p = out.problem;
    p.gauss = gauss;
    p.guess = options.guess;
    p.free_lapse = options.free_lapse && options.max_lapse > 0.0;
    p.lapse = options.free_lapse ? 0.0 : options.lapse;
    for (const PsychometricBin& b : bins) {
        p.u.push_back(to_u(gauss, b.x));
        p.k.push_back(b.n_correct);
        p.n.push_back(b.n_trials);
    }
    const double u_min = p.u.front(), u_max = p.u.back(), span = u_max - u_min;
    Bounds& bounds = out.bounds;
    // The steepest function allowed rises within a hundredth of the closest two
    // intensities tested (and of 1e-4 of their range), so that a jump between two
    // neighbours shows as one: F near 0 at one and near 1 at the other.
    double gap = span;
    for (std::size_t i = 1; i < p.u.size(); ++i)
        if (p.u[i] > p.u[i - 1]) gap = std::min(gap, p.u[i] - p.u[i - 1]);
    bounds.lower = {u_min - 10.0 * span, std::log(std::min(span * 1e-4, gap * 1e-2))};
    bounds.upper = {u_max + 10.0 * span, std::log(span * 1e2)};
    if (p.free_lapse) {
        bounds.lower.push_back(0.0);
        bounds.upper.push_back(options.max_lapse);
    }
    for (double fm : {0.25, 0.5, 0.75})
        for (double fs : {0.05, 0.2, 1.0}) {
            std::vector<double> start{u_min + fm * span, std::log(fs * span)};
            if (p.free_lapse) start.push_back(options.max_lapse / 3.0);
            const Search s = minimise(p, bounds, start);
            if (s.value < out.best.value) out.best = s;
        }
    return out;
}

}  // namespace

double psychometric_f(PsychometricFamily family, double x, double alpha, double beta) {
    if (gaussian(family)) return g_cdf(true, (x - alpha) / beta);
    if (x <= 0.0) return 0.0;
    return g_cdf(false, beta * (std::log(x) - std::log(alpha)));
}

double psychometric_psi(const PsychometricFit& fit, double x) {
    if (!fit.fitted) return fit.guess;
    return fit.guess + (1.0 - fit.guess - *fit.lapse) *
                           psychometric_f(fit.family, x, *fit.alpha, *fit.beta);
}

std::vector<PsychometricBin> bin_trials(const std::vector<PsychometricTrial>& trials) {
    std::map<double, PsychometricBin> bins;
    for (std::size_t i = 0; i < trials.size(); ++i) {
        const double x = trials[i].x;
        if (!std::isfinite(x))
            throw InputError("psychometric function: trial " + std::to_string(i + 1) +
                             " has no finite intensity");
        PsychometricBin& b = bins[x == 0.0 ? 0.0 : x];
        b.x = x;
        ++b.n_trials;
        if (trials[i].correct) ++b.n_correct;
    }
    std::vector<PsychometricBin> out;
    for (const auto& [x, b] : bins) out.push_back(b);
    return out;
}

PsychometricFit fit_psychometric(const std::vector<PsychometricTrial>& trials,
                                 const PsychometricOptions& options) {
    if (!gaussian(options.family))
        for (std::size_t i = 0; i < trials.size(); ++i)
            if (!(trials[i].x > 0.0) && std::isfinite(trials[i].x))
                throw InputError(
                    "psychometric function: the Weibull needs positive "
                    "intensities; trial " +
                    std::to_string(i + 1) + " has x = " + short_text(trials[i].x));
    return fit_psychometric(bin_trials(trials), options);
}

PsychometricFit fit_psychometric(const std::vector<PsychometricBin>& input,
                                 const PsychometricOptions& options) {
    check_options(options);
    PsychometricFit fit;
    fit.family = options.family;
    fit.guess = options.guess;
    fit.lapse_free = options.free_lapse && options.max_lapse > 0.0;
    fit.threshold_level = options.threshold_level;
    fit.p_correct_level = options.p_correct_level;
    fit.threshold = not_identified();
    if (options.p_correct_level) fit.threshold_p = not_identified();
    const bool gauss = gaussian(options.family);
    fit.bins = checked_bins(input, gauss);
    for (const PsychometricBin& b : fit.bins) {
        fit.trials += b.n_trials;
        fit.correct += b.n_correct;
    }
    if (fit.trials == 0) {
        fit.notes.push_back("No trials: there is no psychometric function to fit.");
        return fit;
    }
    const Summary summary = summary_of(fit);
    if (settled_without_a_fit(fit, summary, options)) return fit;
    const double x_min = summary.x_min, x_max = summary.x_max;
    const double proportion = summary.proportion;
    const std::string& tally = summary.tally;

    const LikelihoodFit ml = maximum_likelihood(fit.bins, options, gauss);
    const Problem& p = ml.problem;
    const Bounds& bounds = ml.bounds;
    const Search& best = ml.best;
    const double u_min = p.u.front(), u_max = p.u.back();
    if (!std::isfinite(best.value)) {
        fit.notes.push_back("The likelihood could not be maximised.");
        return fit;
    }
    const auto parameters_of = [&](const std::vector<double>& theta) {
        return State{theta[0], std::exp(theta[1]), p.free_lapse ? theta[2] : p.lapse};
    };
    const State st = parameters_of(best.theta);
    fit.fitted = true;
    fit.converged = best.converged;
    fit.parameters = static_cast<int>(best.theta.size());
    fit.alpha = gauss ? st.m : std::exp(st.m);
    fit.beta = gauss ? st.s : 1.0 / st.s;
    fit.lapse = st.lapse;
    double log_choose_sum = 0.0, constant = 0.0;
    for (const PsychometricBin& b : fit.bins) {
        log_choose_sum += log_choose(b.n_trials, b.n_correct);
        if (b.n_correct > 0) constant += b.n_correct * std::log(proportion);
        if (b.n_correct < b.n_trials)
            constant += (b.n_trials - b.n_correct) * std::log1p(-proportion);
    }
    const double ll = -best.value;
    fit.log_likelihood = ll + log_choose_sum;
    // Deviance against the saturated model, term by term.
    const auto deviance_of = [&](const State& s, const std::vector<double>& k) {
        double dev = 0.0;
        const double range = 1.0 - p.guess - s.lapse;
        for (std::size_t i = 0; i < p.u.size(); ++i) {
            const double z = (p.u[i] - s.m) / s.s;
            const double psi = std::max(p.guess + range * g_cdf(gauss, z), kTiny);
            const double q = std::max(s.lapse + range * g_ccdf(gauss, z), kTiny);
            const double wrong = p.n[i] - k[i];
            if (k[i] > 0) dev += k[i] * std::log(k[i] / (p.n[i] * psi));
            if (wrong > 0) dev += wrong * std::log(wrong / (p.n[i] * q));
        }
        return std::max(0.0, 2.0 * dev);
    };
    const double deviance = deviance_of(st, p.k);
    fit.deviance = deviance;
    fit.deviance_df = static_cast<int>(fit.bins.size()) - fit.parameters;
    if (fit.deviance_df >= 1)
        fit.deviance_p = finite(boost::math::cdf(boost::math::complement(
            boost::math::chi_squared(fit.deviance_df), deviance)));
    fit.constant_df = fit.parameters - 1;
    const double lr = std::max(0.0, 2.0 * (ll - constant));
    fit.constant_chi2 = lr;
    fit.constant_p = finite(boost::math::cdf(
        boost::math::complement(boost::math::chi_squared(fit.constant_df), lr)));

    // The slope is not identified when no tested intensity lies on the rising part of F
    // (every fitted F within 0.001 of 0 or 1): the responses jump between two levels and
    // the likelihood only grows as the function steepens. With F near 0 at some
    // intensities and near 1 at the others, the jump is between the largest of the first
    // and the smallest of the second, neighbours (F rises with x). A function as steep as
    // its bound allows, its middle within the range, is such a jump too: between the
    // intensities either side of its middle.
    struct Rise {
        bool off_slope = true, low = false, high = false;
        std::size_t last_low = 0, first_high = 0;
        bool jump() const { return off_slope && low && high; }
    };
    const double s_min = std::exp(bounds.lower[1]);
    const auto rise_of = [&](const State& s) {
        Rise r;
        for (std::size_t i = 0; i < p.u.size(); ++i) {
            const double f = g_cdf(gauss, (p.u[i] - s.m) / s.s);
            if (f > 1e-3 && f < 1.0 - 1e-3) r.off_slope = false;
            if (f <= 1e-3) {
                r.low = true;
                r.last_low = i;
            } else if (!r.high) {
                r.high = true;
                r.first_high = i;
            }
        }
        if (!r.off_slope && s.s <= s_min * (1.0 + 1e-6) && s.m >= u_min && s.m < u_max) {
            r = Rise{};
            r.low = r.high = true;
            while (r.last_low + 1 < p.u.size() && p.u[r.last_low + 1] <= s.m)
                ++r.last_low;
            r.first_high = r.last_low + 1;
        }
        return r;
    };
    const Rise rise = rise_of(st);
    const bool off_slope = rise.off_slope;
    const bool steepest = rise.jump();
    // F as flat as the bounds allow: no change over the range tested.
    const bool flattest = best.theta[1] >= bounds.upper[1] - 1e-6;
    if (p.free_lapse && st.lapse >= options.max_lapse - 1e-7)
        fit.notes.push_back("The lapse rate is at its upper bound " +
                            short_text(options.max_lapse) +
                            ": errors at the highest intensities pull it there; the "
                            "threshold and slope may be biased (fix the lapse rate or "
                            "test higher intensities).");
    // No threshold when psi does not change with intensity: the fit is as flat as its
    // bounds allow, or the rise is not significant and the answers are at chance. An
    // adaptive track keeps its trials near the threshold, where psi changes least over
    // the deltas it tries, so a participant above chance whose rise is not significant
    // still has the fitted threshold, with a note and its bootstrap interval.
    double p_above = 1.0;
    if (options.guess > 0.0 && fit.correct > 0) {
        const boost::math::binomial_distribution<> chance(fit.trials, options.guess);
        p_above = boost::math::cdf(
            boost::math::complement(chance, static_cast<double>(fit.correct - 1)));
    }
    const bool above_chance = options.guess > 0.0 && p_above < options.test_level;
    const bool rise_significant = fit.constant_p.value_or(1.0) < options.test_level;
    const std::string constant_test =
        "likelihood-ratio test against a constant " + short_text(proportion) + ": chi2(" +
        std::to_string(fit.constant_df) + ") = " + short_text(lr) +
        ", p = " + format_p_short(fit.constant_p);
    const std::string chance_test =
        options.guess > 0.0 ? (above_chance ? ", above chance (guess rate "
                                            : ", at chance (guess rate ") +
                                  short_text(options.guess) +
                                  ", binomial test p = " + format_p_short(p_above) + ")"
                            : std::string();
    if (flattest || (!rise_significant && !above_chance)) {
        fit.notes.push_back(
            "No threshold: the proportion correct does not change with intensity (" +
            constant_test + "); " + tally + chance_test + ".");
        return fit;
    }
    if (!rise_significant)
        fit.notes.push_back(
            "The rise with intensity is not significant (" + constant_test +
            "), as on "
            "an adaptive track that keeps its trials near the threshold; " +
            tally + chance_test +
            ", so the threshold is the fit's, its uncertainty the "
            "bootstrap interval.");

    if (steepest)
        fit.notes.push_back(
            "The responses jump between two neighbouring intensities, " +
            short_text(fit.bins[rise.last_low].x) + " and " +
            short_text(fit.bins[rise.first_high].x) +
            ": the slope is steeper than these intensities can measure (not "
            "identified), so the threshold lies anywhere between them; no value and no "
            "interval is given (test intensities between them to measure it).");

    // Thresholds and slopes.
    const auto make = [&](double f_level, const std::string& name) {
        if (steepest) {
            Threshold t;
            t.status = ThresholdStatus::between;
            t.between_low = fit.bins[rise.last_low].x;
            t.between_high = fit.bins[rise.first_high].x;
            t.text = "between " + short_text(*t.between_low) + " and " +
                     short_text(*t.between_high);
            return t;
        }
        const auto [x, slope] = threshold_at(p, st, f_level);
        if (x < x_min) {
            fit.notes.push_back("The " + name +
                                " is below the smallest intensity tested, " +
                                short_text(x_min) + ".");
            return bounded(ThresholdStatus::below_range, x_min);
        }
        if (x > x_max) {
            fit.notes.push_back("The " + name +
                                " is above the largest intensity tested, " +
                                short_text(x_max) + ".");
            return bounded(ThresholdStatus::above_range, x_max);
        }
        Threshold t;
        t.status = ThresholdStatus::estimated;
        t.value = x;
        if (!off_slope) t.slope = finite(slope);
        t.text = short_text(x);
        return t;
    };
    fit.threshold = make(options.threshold_level, "threshold");
    std::optional<double> f_p;
    if (options.p_correct_level) {
        const double f =
            (*options.p_correct_level - options.guess) / (1.0 - options.guess - st.lapse);
        if (f < 1.0) {
            f_p = f;
            fit.threshold_p =
                make(f, "threshold at " + short_text(100.0 * *options.p_correct_level) +
                            "% correct");
        } else {
            fit.notes.push_back("The fitted function never reaches " +
                                short_text(100.0 * *options.p_correct_level) +
                                "% correct (its ceiling is " +
                                short_text(100.0 * (1.0 - st.lapse)) + "%).");
        }
    }

    // Stage 4, the parametric bootstrap. Each resample follows the point estimate's
    // rules: a threshold outside the tested range counts only as below or above it, and
    // a slope that is not identified as steeper than any (a jump) or, with the
    // threshold outside the range, as unknown.
    if (options.bootstrap > 0) {
        std::mt19937_64 rng(options.seed);
        std::vector<Resample> th, thp;
        int exceed = 0;
        std::vector<double> psi(p.u.size());
        for (std::size_t i = 0; i < p.u.size(); ++i)
            psi[i] = p.guess +
                     (1.0 - p.guess - st.lapse) * g_cdf(gauss, (p.u[i] - st.m) / st.s);
        Problem sample = p;
        const auto resample_of = [&](double x, double slope, const Rise& r) {
            Resample out{x, slope, x < x_min ? -1 : (x > x_max ? 1 : 0),
                         SlopeKind::identified};
            if (out.side != 0 || (r.off_slope && !r.jump()))
                out.kind = SlopeKind::unknown;
            else if (r.jump())
                out.kind = SlopeKind::steep;
            return out;
        };
        for (int b = 0; b < options.bootstrap; ++b) {
            for (std::size_t i = 0; i < p.u.size(); ++i) {
                int k = 0;
                for (int t = 0; t < static_cast<int>(p.n[i]); ++t)
                    if (uniform(rng) < psi[i]) ++k;
                sample.k[i] = k;
            }
            const Search s = minimise(sample, bounds, best.theta);
            if (!std::isfinite(s.value)) continue;
            const State ss = parameters_of(s.theta);
            const auto [x, slope] = threshold_at(p, ss, options.threshold_level);
            if (!std::isfinite(x) || !std::isfinite(slope)) continue;
            const Rise r = rise_of(ss);
            if (f_p) {
                const double f = (*options.p_correct_level - options.guess) /
                                 (1.0 - options.guess - ss.lapse);
                if (f >= 1.0) {  // never reaches that proportion: above the range
                    thp.push_back({x_max, 0.0, 1, SlopeKind::unknown});
                } else {
                    const auto [xp, slopep] = threshold_at(p, ss, f);
                    if (!std::isfinite(xp) || !std::isfinite(slopep)) continue;
                    thp.push_back(resample_of(xp, slopep, r));
                }
            }
            th.push_back(resample_of(x, slope, r));
            if (deviance_of(ss, sample.k) >= deviance) ++exceed;
        }
        fit.bootstrap_samples = static_cast<int>(th.size());
        if (!th.empty()) {
            fit.deviance_p_bootstrap = static_cast<double>(exceed) / th.size();
            bootstrap_interval(fit.threshold, th, "threshold", options, x_min, x_max,
                               fit.notes);
            if (fit.threshold_p && !thp.empty())
                bootstrap_interval(*fit.threshold_p, thp,
                                   "threshold at " +
                                       short_text(100.0 * *options.p_correct_level) +
                                       "% correct",
                                   options, x_min, x_max, fit.notes);
        }
    }
    return fit;
}

ParticipantFits fit_psychometric_participants(const std::vector<ParticipantTrial>& trials,
                                              const PsychometricOptions& options) {
    for (std::size_t i = 0; i < trials.size(); ++i) {
        const double x = trials[i].x;
        if (!std::isfinite(x) || (!gaussian(options.family) && x <= 0.0))
            throw InputError(
                "psychometric function: trial " + std::to_string(i + 1) +
                " (participant " + trials[i].participant + ") has x = " +
                (std::isfinite(x) ? short_text(x) : std::string("no number")) +
                (std::isfinite(x) ? "; the Weibull needs positive intensities" : ""));
    }
    std::vector<std::string> order;
    std::map<std::string, std::vector<PsychometricTrial>> by;
    std::vector<PsychometricTrial> all;
    for (const ParticipantTrial& t : trials) {
        auto [it, added] = by.try_emplace(t.participant);
        if (added) order.push_back(t.participant);
        it->second.push_back({t.x, t.correct});
        all.push_back({t.x, t.correct});
    }
    ParticipantFits fits;
    fits.pooled = fit_psychometric(all, options);
    for (const std::string& id : order)
        fits.participants.emplace_back(id, fit_psychometric(by[id], options));
    return fits;
}

}  // namespace lucent::analysis
