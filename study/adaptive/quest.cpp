#include "study/adaptive/quest.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/number_text.h"

namespace lucent::study::adaptive {
namespace {

[[noreturn]] void refuse(const std::string& message) {
    throw std::invalid_argument("quest: " + message);
}

std::string number(double v) { return common::shortest_text(v); }

// numpy's pairwise summation (its add.reduce over a contiguous float64 array), so
// the sums round as PsychoPy's do.
double pairwise_sum(const double* a, std::size_t n) {
    if (n < 8) {
        double sum = 0.0;
        for (std::size_t i = 0; i < n; ++i) sum += a[i];
        return sum;
    }
    if (n <= 128) {
        double r[8];
        for (int j = 0; j < 8; ++j) r[j] = a[j];
        std::size_t i = 8;
        for (; i < n - (n % 8); i += 8)
            for (int j = 0; j < 8; ++j) r[j] += a[i + j];
        double sum = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; ++i) sum += a[i];
        return sum;
    }
    std::size_t half = n / 2;
    half -= half % 8;
    return pairwise_sum(a, half) + pairwise_sum(a + half, n - half);
}

double sum(const std::vector<double>& v) {
    return 0.0 + pairwise_sum(v.data(), v.size());
}

// numpy.interp for one point (xp increasing): the end values outside, the slope
// formula of numpy's compiled loop inside.
double interp(double x, const std::vector<double>& xp, const std::vector<double>& fp) {
    const std::size_t n = xp.size();
    if (std::isnan(x)) return x;
    if (x < xp.front()) return fp.front();
    if (x > xp.back()) return fp.back();
    const std::size_t j =
        static_cast<std::size_t>(std::upper_bound(xp.begin(), xp.end(), x) - xp.begin()) -
        1;
    if (j == n - 1 || xp[j] == x) return fp[j];
    const double slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]);
    double y = slope * (x - xp[j]) + fp[j];
    if (std::isnan(y)) {
        y = slope * (x - xp[j + 1]) + fp[j + 1];
        if (std::isnan(y) && fp[j] == fp[j + 1]) y = fp[j];
    }
    return y;
}

// Python's round(): to the nearest integer, halves to even.
double round_half_even(double v) {
    const double r = std::round(v);  // halves away from zero
    if (std::fabs(v - std::trunc(v)) == 0.5 && std::fmod(r, 2.0) != 0.0)
        return r - std::copysign(1.0, v);
    return r;
}

// The Weibull of quest.py, term by term as numpy evaluates it.
double weibull(double x, double beta, double delta, double gamma) {
    return delta * gamma +
           (1 - delta) * (1 - (1 - gamma) * std::exp(-std::pow(10.0, beta * x)));
}

}  // namespace

QuestMethod parse_quest_method(std::string_view text) {
    if (text == "quantile") return QuestMethod::quantile;
    if (text == "mean") return QuestMethod::mean;
    if (text == "mode") return QuestMethod::mode;
    refuse("method must be 'quantile', 'mean' or 'mode', not '" + std::string(text) +
           "'");
}

std::string_view to_string(QuestMethod method) {
    switch (method) {
        case QuestMethod::quantile:
            return "quantile";
        case QuestMethod::mean:
            return "mean";
        case QuestMethod::mode:
            return "mode";
    }
    return "quantile";
}

Quest::Quest(QuestSettings settings) : settings_(std::move(settings)) {
    const QuestSettings& s = settings_;
    if (!std::isfinite(s.start)) refuse("startVal must be finite");
    if (!(s.start_sd > 0) || !std::isfinite(s.start_sd))
        refuse("startValSd must be positive (got " + number(s.start_sd) + ")");
    if (!(s.p_threshold > 0 && s.p_threshold < 1))
        refuse("pThreshold must lie in (0, 1) (got " + number(s.p_threshold) + ")");
    if (!(s.beta > 0) || !std::isfinite(s.beta))
        refuse("beta must be positive (got " + number(s.beta) + ")");
    if (!(s.delta >= 0 && s.delta < 1))
        refuse("delta must lie in [0, 1) (got " + number(s.delta) + ")");
    if (!(s.gamma >= 0 && s.gamma < 1))
        refuse("gamma must lie in [0, 1) (got " + number(s.gamma) + ")");
    if (s.gamma > s.p_threshold)
        refuse("gamma " + number(s.gamma) + " is above pThreshold " +
               number(s.p_threshold));
    if (!(s.grain > 0) || !std::isfinite(s.grain))
        refuse("grain must be positive (got " + number(s.grain) + ")");
    if (s.range && (!(*s.range > 0) || !std::isfinite(*s.range)))
        refuse("range must be positive (got " + number(*s.range) + ")");
    if (!s.n_trials && !s.stop_interval) refuse("give nTrials or stopInterval (or both)");
    if (s.n_trials && *s.n_trials < 1)
        refuse("nTrials must be at least 1 (got " + std::to_string(*s.n_trials) + ")");
    if (s.stop_interval && (!(*s.stop_interval > 0) || !std::isfinite(*s.stop_interval)))
        refuse("stopInterval must be positive (got " + number(*s.stop_interval) + ")");
    if ((s.min_value && !std::isfinite(*s.min_value)) ||
        (s.max_value && !std::isfinite(*s.max_value)))
        refuse("minVal and maxVal must be finite");
    if (s.min_value && s.max_value && *s.min_value > *s.max_value)
        refuse("minVal " + number(*s.min_value) + " is above maxVal " +
               number(*s.max_value));
    if ((s.min_value && s.start < *s.min_value) ||
        (s.max_value && s.start > *s.max_value))
        refuse("startVal " + number(s.start) + " is outside [minVal, maxVal]");

    // The grid: dim + 1 points, dim even (quest.py's QuestObject.__init__).
    if (s.range) {
        const double grains = 2 * std::ceil(*s.range / s.grain / 2.0);
        if (grains > 2e7)
            refuse("range / grain gives a grid of " + number(grains) +
                   " points (at most 2e7)");
        dim_ = static_cast<long>(grains);
    }
    const long half = dim_ / 2;
    x_.resize(dim_ + 1);
    pdf_.resize(dim_ + 1);
    for (long j = 0; j <= dim_; ++j) {
        x_[j] = static_cast<double>(j - half) * s.grain;
        const double z = x_[j] / s.start_sd;
        pdf_[j] = std::exp(-0.5 * (z * z));
    }
    const double total = sum(pdf_);
    for (double& p : pdf_) p /= total;

    // The psychometric function on the doubled grid, then shifted by epsilon so that
    // it passes pThreshold at 0 (QuestObject.recompute()).
    const std::size_t n2 = static_cast<std::size_t>(2 * dim_ + 1);
    std::vector<double> x2(n2);
    p2_.resize(n2);
    for (std::size_t k = 0; k < n2; ++k) {
        x2[k] = static_cast<double>(static_cast<long>(k) - dim_) * s.grain;
        p2_[k] = weibull(x2[k], s.beta, s.delta, s.gamma);
    }
    if (p2_.front() >= s.p_threshold || p2_.back() <= s.p_threshold)
        refuse("the psychometric function's range [" + number(p2_.front()) + ", " +
               number(p2_.back()) + "] omits pThreshold " + number(s.p_threshold) +
               " (widen range or change beta, gamma, delta)");
    std::vector<double> p_steps, x_steps;  // the strictly increasing subset
    for (std::size_t k = 0; k + 1 < n2; ++k)
        if (p2_[k + 1] - p2_[k] != 0) {
            p_steps.push_back(p2_[k]);
            x_steps.push_back(x2[k]);
        }
    if (p_steps.size() < 2)
        refuse("the psychometric function has fewer than 2 strictly increasing points");
    x_threshold_ = interp(s.p_threshold, p_steps, x_steps);
    for (std::size_t k = 0; k < n2; ++k)
        p2_[k] = weibull(x2[k] + x_threshold_, s.beta, s.delta, s.gamma);

    // The most informative quantile order (Pelli 1987), as QuestRecompute.
    const double eps = 1e-14;
    const double pL = p2_.front(), pH = p2_.back();
    double pE = pH * std::log(pH + eps) - pL * std::log(pL + eps) +
                (1 - pH + eps) * std::log(1 - pH + eps) -
                (1 - pL + eps) * std::log(1 - pL + eps);
    pE = 1 / (1 + std::exp(pE / (pL - pH)));
    quantile_order_ = (pE - pL) / (pH - pL);

    next_intensity_ = s.start;
}

bool Quest::hit_range() const {
    return std::find(clamped_.begin(), clamped_.end(), true) != clamped_.end();
}

Proposal Quest::next() {
    if (finished_) throw std::logic_error("quest: next() after QUEST finished");
    if (pending_)
        throw std::logic_error("quest: next() before the response to trial " +
                               std::to_string(intensities_.size() - 1));
    pending_ = true;
    intensities_.push_back(next_intensity_);
    clamped_.push_back(next_clamped_);
    return {next_intensity_, next_clamped_};
}

void Quest::add_response(bool correct, std::optional<double> shown) {
    if (!pending_) throw std::logic_error("quest: a response without a trial (next())");
    if (shown && !std::isfinite(*shown))
        throw std::invalid_argument("quest: the intensity shown must be finite");
    pending_ = false;
    if (shown) intensities_.back() = *shown;
    update(intensities_.back(), correct);
    responses_.push_back(correct ? 1 : 0);

    const QuestSettings& s = settings_;
    if (s.n_trials && static_cast<int>(intensities_.size()) >= *s.n_trials)
        finished_ = true;
    else if (s.stop_interval && conf_interval_width() < *s.stop_interval)
        finished_ = true;
    if (!finished_) choose_next();
}

// QuestUpdate: multiply the posterior by the likelihood of the answer, the
// psychometric function read at (intensity - start) / grain grains from each candidate
// threshold; an intensity off the table is taken at the table's end.
void Quest::update(double intensity, bool correct) {
    const double inten = std::max(-1e10, std::min(1e10, intensity));
    const long long r = static_cast<long long>(
        round_half_even((inten - settings_.start) / settings_.grain));
    const long long n2 = static_cast<long long>(p2_.size());
    const long long half = dim_ / 2;
    // Index into the reversed table s2 of candidate j: dim + (j - dim/2) - r.
    long long first = dim_ - half - r;
    const long long last = first + dim_;
    if (first < 0)
        first = 0;
    else if (last > n2 - 1)
        first -= last - (n2 - 1);

    std::vector<double> next(pdf_.size());
    bool any = false;
    double peak = 0;
    for (std::size_t j = 0; j < pdf_.size(); ++j) {
        const double p = p2_[static_cast<std::size_t>(n2 - 1 - (first + (long long)j))];
        next[j] = pdf_[j] * (correct ? p : 1 - p);
        any |= next[j] != 0;
        peak = std::max(peak, next[j]);
    }
    // With delta = 0 an answer can be impossible at every candidate: keep the posterior.
    if (!any) return;
    // Rescale by a power of two before the product underflows: exact, so every
    // statistic keeps its value.
    int exponent = 0;
    std::frexp(peak, &exponent);
    if (exponent < -500 || exponent > 500)
        for (double& p : next) p = std::ldexp(p, -exponent);
    pdf_ = std::move(next);
}

void Quest::choose_next() {
    const QuestSettings& s = settings_;
    double v = 0;
    switch (s.method) {
        case QuestMethod::quantile:
            v = quantile();
            break;
        case QuestMethod::mean:
            v = mean();
            break;
        case QuestMethod::mode:
            v = mode();
            break;
    }
    next_clamped_ = false;
    if (s.max_value && v > *s.max_value) {
        v = *s.max_value;
        next_clamped_ = true;
    } else if (s.min_value && v < *s.min_value) {
        v = *s.min_value;
        next_clamped_ = true;
    }
    next_intensity_ = v;
}

double Quest::mean() const {
    std::vector<double> weighted(pdf_.size());
    for (std::size_t j = 0; j < pdf_.size(); ++j) weighted[j] = pdf_[j] * x_[j];
    return settings_.start + sum(weighted) / sum(pdf_);
}

double Quest::mode() const {
    const auto peak = std::max_element(pdf_.begin(), pdf_.end());
    return x_[static_cast<std::size_t>(peak - pdf_.begin())] + settings_.start;
}

double Quest::quantile(std::optional<double> p) const {
    const double order = p.value_or(quantile_order_);
    if (!(order >= 0 && order <= 1))
        throw std::invalid_argument("quest: a quantile's order must lie in [0, 1] (got " +
                                    number(order) + ")");
    std::vector<double> cumulative(pdf_.size());
    double running = 0;
    for (std::size_t j = 0; j < pdf_.size(); ++j) cumulative[j] = running += pdf_[j];
    // The points where the cumulative sum moves (the first one always).
    std::vector<double> c_steps, x_steps;
    double before = -1;
    for (std::size_t j = 0; j < pdf_.size(); ++j) {
        if (cumulative[j] - before != 0) {
            c_steps.push_back(cumulative[j]);
            x_steps.push_back(x_[j]);
        }
        before = cumulative[j];
    }
    // PsychoPy raises with fewer than two; the one point is the whole posterior.
    if (c_steps.size() < 2) {
        const auto peak = std::max_element(pdf_.begin(), pdf_.end());
        return settings_.start + x_[static_cast<std::size_t>(peak - pdf_.begin())];
    }
    return settings_.start + interp(order * cumulative.back(), c_steps, x_steps);
}

double Quest::sd() const {
    std::vector<double> first(pdf_.size()), second(pdf_.size());
    for (std::size_t j = 0; j < pdf_.size(); ++j) {
        first[j] = pdf_[j] * x_[j];
        second[j] = pdf_[j] * (x_[j] * x_[j]);
    }
    const double p = sum(pdf_);
    const double m = sum(first) / p;
    return std::sqrt(std::max(0.0, sum(second) / p - m * m));
}

std::pair<double, double> Quest::conf_interval() const {
    return {quantile(0.05), quantile(0.95)};
}

double Quest::conf_interval_width() const {
    const auto [lo, hi] = conf_interval();
    return std::fabs(lo - hi);
}

}  // namespace lucent::study::adaptive
