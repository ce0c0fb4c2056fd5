// Studentized range distribution (design: shared/analysis/studentized-range.md).
//
// Per k, a table of the range tails of k standard normals (df = infinity), built once:
// piecewise Chebyshev series of
//   h(w) = log W(w) - m log w   below the median range (W = P(range <= w) ~ w^m at 0)
//   g(w) = log U(w) + w^2 / 4   above it               (U = P(range > w) ~ e^(-w^2/4))
// with m = k - 1; both are smooth and of moderate size, and every tail keeps its digits.
// At finite df, with u = log S and its density gd(u) (S = sqrt(chi2_df / df)),
//   P(Q > q) = Int gd(u) U(q e^u) du,   P(Q <= q) = Int gd(u) W(q e^u) du,
// summed by the trapezoid rule on the grid u_i = i h (exponentially accurate for these
// analytic, fast-decaying integrands) in log space, marching out from the peak. Only the
// smaller tail is summed; the other is one minus it.
#include "analysis/stats/studentized_range.h"

#include <algorithm>
#include <array>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace lucent::analysis {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr double kLogSqrt2Pi = 0.91893853320467274178;
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
// Above this df the density of log S is so narrow that df = infinity is exact to 1e-12.
constexpr double kDfTreatedAsInfinite = 1e12;

// ---------------------------------------------------------------------------------------
// Normal tails in log space.

// log P(Z > x): erfc while it is a normal double, then the asymptotic series
// Q(x) = phi(x) / x * (1 - 1/x^2 + 3/x^4 - ...) (8 terms: below 1e-16 at x = 37).
double log_normal_upper(double x) {
    if (x < 37.0) return std::log(0.5 * std::erfc(x * kInvSqrt2));
    const double r = 1.0 / (x * x);
    double term = 1.0, series = 1.0;
    for (int n = 1; n <= 8; ++n) {
        term *= -(2.0 * n - 1.0) * r;
        series += term;
    }
    return -0.5 * x * x - kLogSqrt2Pi - std::log(x) + std::log(series);
}

double log_normal_pdf(double x) { return -0.5 * x * x - kLogSqrt2Pi; }

// Gauss-Legendre rule on [-1, 1] (Boost stores the nonnegative half).
template <unsigned N>
struct GaussRule {
    static_assert(N % 2 == 0);
    std::array<double, N> x{}, log_weight{};
    GaussRule() {
        using Boost = boost::math::quadrature::gauss<double, N>;
        for (unsigned j = 0; j < N / 2; ++j) {
            x[2 * j] = Boost::abscissa()[j];
            x[2 * j + 1] = -Boost::abscissa()[j];
            log_weight[2 * j] = log_weight[2 * j + 1] = std::log(Boost::weights()[j]);
        }
    }
};
const GaussRule<10>& short_rule() {
    static const GaussRule<10> rule;
    return rule;
}
const GaussRule<12>& panel_rule() {
    static const GaussRule<12> rule;
    return rule;
}

// log P(z < Z <= z + w). A short interval is integrated directly (10-point Gauss-Legendre
// is exact to rounding on a width below 1, and relative to the mass); otherwise the
// difference is taken in whichever tail the interval lies, where it cannot cancel.
double log_normal_mass(double z, double w) {
    if (w < 1.0) {
        const auto& rule = short_rule();
        const double half = 0.5 * w, center = z + half;
        double top = kNegInf;
        std::array<double, 10> logs{};
        for (int j = 0; j < 10; ++j) {
            logs[j] = log_normal_pdf(center + half * rule.x[j]) + rule.log_weight[j];
            top = std::max(top, logs[j]);
        }
        if (top == kNegInf) return kNegInf;
        double sum = 0.0;
        for (double l : logs) sum += std::exp(l - top);
        return top + std::log(sum * half);
    }
    const bool upper_side = z + 0.5 * w >= 0.0;
    const double near = upper_side ? log_normal_upper(z) : log_normal_upper(-(z + w));
    const double far = upper_side ? log_normal_upper(z + w) : log_normal_upper(-z);
    return near + std::log(-std::expm1(far - near));
}

// ---------------------------------------------------------------------------------------
// df = infinity by quadrature (only to build the tables). Conditioning on the minimum z
// of the k normals, the other m = k - 1 lie above it:
//   U(w) = k Int phi(z) Qbar(z)^m [1 - (1 - Qbar(z+w)/Qbar(z))^m] dz
//   W(w) = k Int phi(z) P(z < Z <= z + w)^m dz.

// log of the sum of e^(log_terms).
double log_sum_exp(const std::vector<double>& log_terms) {
    double top = kNegInf;
    for (double l : log_terms) top = std::max(top, l);
    if (top == kNegInf) return kNegInf;
    double sum = 0.0;
    for (double l : log_terms) sum += std::exp(l - top);
    return top + std::log(sum);
}

// 12-point Gauss-Legendre on panels of `panel_width` over [low, high].
template <class LogIntegrand>
double log_integral(LogIntegrand log_f, double low, double high, double panel_width) {
    const int panels = static_cast<int>(std::ceil((high - low) / panel_width));
    const double width = (high - low) / panels, half = 0.5 * width;
    const auto& rule = panel_rule();
    std::vector<double> logs;
    logs.reserve(panels * 12);
    for (int p = 0; p < panels; ++p) {
        const double center = low + (p + 0.5) * width;
        for (int j = 0; j < 12; ++j)
            logs.push_back(log_f(center + half * rule.x[j]) + rule.log_weight[j]);
    }
    return log_sum_exp(logs) + std::log(half);
}

// The minimum of k normals lies in [-12, 10]; with a large range w it sits near -w/2
// (the maximum near +w/2), and the integrand falls like e^(-d^2) a distance d away.
double min_low(double w) { return std::min(-12.0, std::floor(-0.5 * w - 13.0)); }
double min_high(double w) { return std::min(10.0, std::ceil(13.0 - 0.5 * w)); }

// U(w) on unit panels at integer z: the terms that do not depend on w are computed once
// per k (log k phi(z) Qbar(z)^m and log Qbar(z) at every node).
class UpperRangeQuadrature {
public:
    explicit UpperRangeQuadrature(int k) : m_(k - 1.0), log_m_(std::log(m_)) {
        const auto& rule = panel_rule();
        const double log_k = std::log(static_cast<double>(k));
        for (int panel = kLow; panel < kHigh; ++panel)
            for (int j = 0; j < 12; ++j) {
                const double z = panel + 0.5 + 0.5 * rule.x[j];
                const double log_above = log_normal_upper(z);
                nodes_.push_back({z, log_above,
                                  rule.log_weight[j] + std::log(0.5) + log_k +
                                      log_normal_pdf(z) + m_ * log_above});
            }
    }
    double log_upper(double w) const {
        const int first = (static_cast<int>(min_low(w)) - kLow) * 12;
        const int last = (static_cast<int>(min_high(w)) - kLow) * 12;
        std::vector<double> logs;
        logs.reserve(last - first);
        for (int i = first; i < last; ++i) {
            const Node& n = nodes_[i];
            const double log_ratio = log_normal_upper(n.z + w) - n.log_above;
            // 1 - (1 - r)^m, which is m r to rounding once r underflows.
            const double log_spread =
                log_ratio < -700.0
                    ? log_m_ + log_ratio
                    : std::log(-std::expm1(m_ * std::log1p(-std::exp(log_ratio))));
            logs.push_back(n.log_rest + log_spread);
        }
        return log_sum_exp(logs);
    }

private:
    static constexpr int kLow = -43, kHigh = 10;  // min_low(60), min_high(0)
    struct Node {
        double z, log_above, log_rest;
    };
    double m_, log_m_;
    std::vector<Node> nodes_;
};

double log_range_lower_by_quadrature(double w, int k) {
    const double m = k - 1.0, log_k = std::log(static_cast<double>(k));
    auto log_f = [&](double z) {
        return log_k + log_normal_pdf(z) + m * log_normal_mass(z, w);
    };
    // With a small range all k normals sit together: the integrand is as narrow as
    // phi(z)^k (sd 1/sqrt k). It is log-concave (a product of log-concave factors), so
    // only the stretch within e^-60 of its peak counts: golden-section search for the
    // peak, then panels outward until the integrand has fallen that far.
    const double panel = std::min(1.0, 2.5 / std::sqrt(double(k)));
    constexpr double kGolden = 0.6180339887498949;
    double a = min_low(w), b = min_high(w);
    double x1 = b - kGolden * (b - a), x2 = a + kGolden * (b - a);
    double f1 = log_f(x1), f2 = log_f(x2);
    for (int i = 0; i < 40; ++i) {
        if (f1 < f2) {
            a = x1, x1 = x2, f1 = f2;
            x2 = a + kGolden * (b - a), f2 = log_f(x2);
        } else {
            b = x2, x2 = x1, f2 = f1;
            x1 = b - kGolden * (b - a), f1 = log_f(x1);
        }
    }
    const double peak = 0.5 * (a + b), top = log_f(peak);
    double low = peak, high = peak;
    while (low > min_low(w) && log_f(low) > top - 60.0) low -= panel;
    while (high < min_high(w) && log_f(high) > top - 60.0) high += panel;
    return log_integral(log_f, low, high, panel);
}

// ---------------------------------------------------------------------------------------
// The per-k table.

constexpr int kChebyshevTerms = 17;  // degree 16
constexpr std::array<double, 15> kBreaks = {0, 1,  2,  3,  4,  5,  6, 7,
                                            8, 10, 12, 16, 24, 40, 60};
constexpr int kPanels = static_cast<int>(kBreaks.size()) - 1;
constexpr double kTableEnd = 60.0;  // U(60) ~ 1e-390: beyond, g falls like -log w

struct ChebyshevPanel {
    double mid = 0, half = 1;
    std::array<double, kChebyshevTerms> value{}, slope{};  // f and f' coefficients

    static double sum(const std::array<double, kChebyshevTerms>& c, double x) {
        double b1 = 0.0, b2 = 0.0;
        for (int i = kChebyshevTerms - 1; i >= 1; --i) {
            const double b0 = 2.0 * x * b1 - b2 + c[i];
            b2 = b1;
            b1 = b0;
        }
        return x * b1 - b2 + c[0];
    }
    double at(double w) const { return sum(value, (w - mid) / half); }
    double derivative_at(double w) const { return sum(slope, (w - mid) / half); }
};

template <class F>
ChebyshevPanel fit_panel(double a, double b, F f) {
    constexpr int n = kChebyshevTerms;
    ChebyshevPanel panel;
    panel.mid = 0.5 * (a + b);
    panel.half = 0.5 * (b - a);
    std::array<double, n> samples{};
    for (int j = 0; j < n; ++j)  // Chebyshev points of the first kind (never the ends)
        samples[j] = f(panel.mid + panel.half * std::cos(kPi * (j + 0.5) / n));
    std::array<double, n> c{};
    for (int i = 0; i < n; ++i) {
        double s = 0.0;
        for (int j = 0; j < n; ++j) s += samples[j] * std::cos(kPi * i * (j + 0.5) / n);
        c[i] = 2.0 * s / n;
    }
    // Derivative coefficients: d_{i-1} = d_{i+1} + 2 i c_i (c_0 and d_0 count half).
    std::array<double, n + 1> d{};
    for (int i = n - 1; i >= 1; --i) d[i - 1] = d[i + 1] + 2.0 * i * c[i];
    for (int i = 0; i < n; ++i) {
        panel.value[i] = c[i];
        panel.slope[i] = d[i] / panel.half;
    }
    panel.value[0] *= 0.5;
    panel.slope[0] *= 0.5;
    return panel;
}

int panel_of(double w) {
    if (w < 8.0) return static_cast<int>(w);
    if (w < 10.0) return 8;
    if (w < 12.0) return 9;
    if (w < 16.0) return 10;
    if (w < 24.0) return 11;
    if (w < 40.0) return 12;
    return 13;
}

struct RangeTable {
    int k = 0;
    double m = 0;
    int first_upper_panel = 0;  // panels below hold h, from here on g
    std::array<ChebyshevPanel, kPanels> panels;
    double g_at_end = 0;  // g(60)
    double median = 0;    // U(median) = 1/2
    // Small ranges: h(w) = h0 + h2 w^2 + O(w^4) (h is even), and below closed_range
    // W(w) = e^h0 w^m (1 + h2 w^2) to 1e-17 absolute (for large k because both are
    // below that).
    double h0 = 0, h2 = 0, closed_range = 0;

    double log_upper(double w) const { return log_upper(w, std::log(w)); }
    double log_lower(double w) const { return log_lower(w, std::log(w)); }
    // With log w known (the trapezoid nodes have it for free).
    double log_upper(double w, double log_w) const {
        if (!(w > 0.0)) return 0.0;
        if (w >= kTableEnd)
            return g_at_end - (log_w - std::log(kTableEnd)) - 0.25 * w * w;
        const int p = panel_of(w);
        const double v = panels[p].at(w);
        if (p >= first_upper_panel) return v - 0.25 * w * w;
        return std::log1p(-std::exp(v + m * log_w));
    }
    double log_lower(double w, double log_w) const {
        if (!(w > 0.0)) return kNegInf;
        if (w >= kTableEnd) return std::log1p(-std::exp(log_upper(w, log_w)));
        const int p = panel_of(w);
        const double v = panels[p].at(w);
        if (p < first_upper_panel) return v + m * log_w;
        return std::log(-std::expm1(v - 0.25 * w * w));
    }
    // log of the range density -U'(w) = W'(w).
    double log_density(double w) const {
        if (!(w > 0.0)) return k == 2 ? -0.5 * std::log(kPi) : kNegInf;
        if (w >= kTableEnd) return log_upper(w) + std::log(0.5 * w + 1.0 / w);
        const int p = panel_of(w);
        const ChebyshevPanel& panel = panels[p];
        if (p >= first_upper_panel)
            return panel.at(w) - 0.25 * w * w +
                   std::log(0.5 * w - panel.derivative_at(w));
        return panel.at(w) + m * std::log(w) + std::log(panel.derivative_at(w) + m / w);
    }
};

std::unique_ptr<RangeTable> build_range_table(int k) {
    auto table = std::make_unique<RangeTable>();
    table->k = k;
    table->m = k - 1.0;
    // Switch from W to U at the integer range nearest the median, so that neither side
    // ever takes 1 minus a number near 1.
    const UpperRangeQuadrature upper(k);
    int split = 1;
    double closest = 1.0;
    for (int w = 1; w <= 8; ++w) {
        const double distance = std::fabs(std::exp(upper.log_upper(w)) - 0.5);
        if (distance < closest) closest = distance, split = w;
    }
    table->first_upper_panel = split;  // panel p spans [p, p + 1] up to 8
    const double m = table->m;
    for (int p = 0; p < kPanels; ++p) {
        const double a = kBreaks[p], b = kBreaks[p + 1];
        if (p < split)
            table->panels[p] = fit_panel(a, b, [&](double w) {
                return log_range_lower_by_quadrature(w, k) - m * std::log(w);
            });
        else
            table->panels[p] = fit_panel(
                a, b, [&](double w) { return upper.log_upper(w) + 0.25 * w * w; });
    }
    table->g_at_end = table->panels[kPanels - 1].at(kTableEnd);
    // h0 and h2 = h''(0) / 2 from panel 0's series (differentiated once more).
    {
        const ChebyshevPanel& first = table->panels[0];
        std::array<double, kChebyshevTerms> curvature{};
        std::array<double, kChebyshevTerms + 1> d{};
        for (int i = kChebyshevTerms - 1; i >= 1; --i)
            d[i - 1] = d[i + 1] + 2.0 * i * first.slope[i];
        for (int i = 0; i < kChebyshevTerms; ++i) curvature[i] = d[i] / first.half;
        curvature[0] *= 0.5;
        table->h0 = first.at(0.0);
        table->h2 = 0.5 * ChebyshevPanel::sum(curvature, -1.0);
    }
    // The two-term form's error |W - e^h0 w^m (1 + h2 w^2)| falls with w: bisect in
    // log w for where it reaches 1e-17.
    {
        auto error = [&](double w) {
            const double h = table->panels[panel_of(w)].at(w);
            const double ratio = std::exp(table->h0 - h);
            return std::exp(h + m * std::log(w)) *
                   std::fabs(-std::expm1(table->h0 - h) - ratio * table->h2 * w * w);
        };
        // (Up to the first U panel; with many groups W is far below 1e-17 there.)
        double lo = -60.0, hi = std::log(static_cast<double>(split));  // log w
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            (error(std::exp(mid)) < 1e-17 ? lo : hi) = mid;
        }
        table->closed_range = std::exp(lo);
    }
    // U is monotone: bisect on the table.
    double lo = 0.0, hi = kTableEnd;
    for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        (table->log_upper(mid) > std::log(0.5) ? lo : hi) = mid;
    }
    table->median = 0.5 * (lo + hi);
    return table;
}

const RangeTable& range_table(int k) {
    static std::array<std::once_flag, kMaxRangeGroups + 1> once;
    static std::array<std::unique_ptr<RangeTable>, kMaxRangeGroups + 1> tables;
    std::call_once(once[k], [k] { tables[k] = build_range_table(k); });
    return *tables[k];
}

// ---------------------------------------------------------------------------------------
// The density of u = log S, S = sqrt(chi2_nu / nu), in a form that keeps its digits for
// huge nu:  log gd(u) = c(nu) - nu (e^(2u) - 1 - 2u) / 2,
//           c(nu) = log 2 + log(nu / (4 pi)) / 2 - stirling(nu / 2).

// lgamma(a) - [(a - 1/2) log a - a + log(2 pi) / 2].
double stirling_remainder(double a) {
    if (a < 20.0) return std::lgamma(a) - ((a - 0.5) * std::log(a) - a + kLogSqrt2Pi);
    const double r = 1.0 / a, r2 = r * r;
    return r * (1.0 / 12 -
                r2 * (1.0 / 360 - r2 * (1.0 / 1260 - r2 * (1.0 / 1680 - r2 / 1188))));
}

// e^x - 1 - x without cancellation near 0.
double exp_minus_one_minus_x(double x) {
    if (std::fabs(x) >= 0.5) return std::expm1(x) - x;
    double term = 1.0, sum = 0.0;  // x^2/2! (1 + x/3 + x^2/(3*4) + ...)
    for (int n = 3; n <= 22; ++n) {
        sum += term;
        term *= x / n;
    }
    return 0.5 * x * x * sum;
}

double log_scale_density_constant(double df) {
    return std::log(2.0) + 0.5 * std::log(df / (4.0 * kPi)) -
           stirling_remainder(0.5 * df);
}

// The trapezoid grid u_i = i * step for one (df, step): log(step * gd(u_i)) and e^(u_i),
// filled lazily outward from the first index asked for and kept per thread, so a run of
// evaluations at one df costs one table lookup and one exp per node.
class ScaleGrid {
public:
    struct Node {
        double log_weight, scale;
    };
    ScaleGrid() = default;
    ScaleGrid(double df, double step, int anchor)
        : df_(df),
          step_(step),
          anchor_(anchor),
          log_constant_(log_scale_density_constant(df) + std::log(step)) {}
    bool matches(double df, double step) const { return df_ == df && step_ == step; }
    double df() const { return df_; }
    double step() const { return step_; }
    double log_constant() const { return log_constant_; }

    Node node(int i) {
        if (i >= anchor_) {
            const std::size_t at = static_cast<std::size_t>(i - anchor_);
            while (right_.size() <= at)
                right_.push_back(compute(anchor_ + int(right_.size())));
            return right_[at];
        }
        const std::size_t at = static_cast<std::size_t>(anchor_ - 1 - i);
        while (left_.size() <= at)
            left_.push_back(compute(anchor_ - 1 - int(left_.size())));
        return left_[at];
    }

private:
    Node compute(int i) const {
        const double u = i * step_;
        return {log_constant_ - 0.5 * df_ * exp_minus_one_minus_x(2.0 * u), std::exp(u)};
    }
    double df_ = 0, step_ = 0;
    int anchor_ = 0;
    double log_constant_ = 0;
    std::vector<Node> right_, left_;
};

ScaleGrid& scale_grid(double df, double step, int anchor) {
    thread_local std::array<ScaleGrid, 4> grids;
    thread_local std::size_t next = 0;
    for (ScaleGrid& grid : grids)
        if (grid.matches(df, step)) return grid;
    ScaleGrid& grid = grids[next++ % grids.size()];
    grid = ScaleGrid(df, step, anchor);
    return grid;
}

// The step. The trapezoid sum of gd errs by twice its Fourier transform at 2 pi / h,
// |E S^(2 pi i / h)| = |Gamma(df/2 + i pi/h) / Gamma(df/2)|, which stays below 1e-16 for
// h <= 0.5 / sqrt(df + 18) (tight near df = 30; ~0.5 / sqrt(df) for large df). For
// large k the range's transition is as sharp as W ~ w^m, hence df + m when larger; and
// the integrands are analytic only in |Im u| < pi/4, hence at most 0.12.
double grid_step(double df, int k) {
    return std::min(0.12, 0.5 / std::sqrt(df + std::max(k - 1.0, 20.0)));
}

// Sum of exp(terms) without overflow or underflow.
class LogSum {
public:
    void add(double log_term) {
        if (log_term == kNegInf) return;
        if (reference_ == kNegInf) {
            reference_ = log_term;
            sum_ = 1.0;
        } else if (log_term > reference_ + 300.0) {
            sum_ = sum_ * std::exp(reference_ - log_term) + 1.0;
            reference_ = log_term;
        } else {
            sum_ += std::exp(log_term - reference_);
        }
    }
    double log_value() const {
        return reference_ == kNegInf ? kNegInf : reference_ + std::log(sum_);
    }

private:
    double reference_ = kNegInf, sum_ = 0.0;
};

enum class Mix { kLower, kUpper, kDensity };

// Terms below e^-34 of the largest are dropped (the rest of a tail adds < 1e-13).
constexpr double kDrop = 34.0;

// h * sum_{j <= i} gd(u_j) U(q e^(u_j)) in closed form, where the range is small enough
// that W(w) = e^h0 w^m (1 + h2 w^2) to rounding: with x = nu e^(2u)/2 small,
//   gd(u) = e^(c + nu/2 + nu u) sum_n (-x)^n / n!,
// and each power of e^u (times 1, w^m = q^m e^(m u) or w^(m+2)) sums over the grid as a
// geometric series.
double log_left_tail(const ScaleGrid& grid, int i, double log_q,
                     const RangeTable& table) {
    const double df = grid.df(), h = grid.step(), u = i * h, m = table.m;
    const double x = 0.5 * df * std::exp(2.0 * u);
    const double log_w = log_q + u, w2 = std::exp(2.0 * log_w);
    const double small_range = std::exp(table.h0 + m * log_w);
    double term = 1.0, density = 0.0, lower = 0.0;
    for (int n = 0; n < 30 && std::fabs(term) > 1e-18; ++n) {
        density += term / -std::expm1(-(df + 2.0 * n) * h);
        lower += term * (1.0 / -std::expm1(-(df + m + 2.0 * n) * h) +
                         table.h2 * w2 / -std::expm1(-(df + m + 2.0 + 2.0 * n) * h));
        term *= -x / (n + 1);
    }
    return grid.log_constant() + 0.5 * df + df * u +
           std::log(density - small_range * lower);
}

// log of h * sum_i gd(u_i) f(q e^(u_i)) with f = W, U or w * (range density).
double log_mix(double q, const RangeTable& table, double df, Mix mix, bool upper_peak) {
    const double h = grid_step(df, table.k);
    const double log_q = std::log(q);
    // Peak of the integrand in u: where gd's curvature meets e^(-(q S)^2/4) (upper tail;
    // not below where q S is a typical range), or (q S)^m (lower tail).
    const double peak_u = upper_peak ? std::max(0.5 * std::log(df / (df + 0.5 * q * q)),
                                                std::log(table.median) - log_q)
                                     : 0.5 * std::log1p(table.m / df);
    const int start = static_cast<int>(std::lround(peak_u / h));
    ScaleGrid& grid = scale_grid(df, h, start);
    auto log_term = [&](int i) {
        const ScaleGrid::Node node = grid.node(i);
        const double w = q * node.scale, log_w = log_q + i * h;
        switch (mix) {
            case Mix::kLower:
                return node.log_weight + table.log_lower(w, log_w);
            case Mix::kUpper:
                return node.log_weight + table.log_upper(w, log_w);
            case Mix::kDensity:
                return node.log_weight + std::log(w) + table.log_density(w);
        }
        return kNegInf;
    };
    // Where W is a short power series in w and so is gd, the rest of the (slow,
    // ~e^(nu u)) upper-tail integrand to the left has a closed form.
    const double closed_u =
        std::min(0.5 * std::log(0.1 / df), std::log(table.closed_range) - log_q);
    constexpr int kMaxNodes = 200000;  // a guard: ~1000 suffice for any argument
    LogSum sum;
    double top = kNegInf;
    for (int i = start; i < start + kMaxNodes; ++i) {
        const double t = log_term(i);
        sum.add(t);
        top = std::max(top, t);
        if (t < top - kDrop) break;
    }
    for (int i = start - 1; i > start - kMaxNodes; --i) {
        if (mix == Mix::kUpper && i * h <= closed_u) {
            sum.add(log_left_tail(grid, i, log_q, table));
            break;
        }
        const double t = log_term(i);
        sum.add(t);
        top = std::max(top, t);
        if (t < top - kDrop) break;
    }
    return sum.log_value();
}

void check_arguments(int k, double df) {
    if (k < kMinRangeGroups || k > kMaxRangeGroups)
        throw std::domain_error("studentized range: k = " + std::to_string(k) +
                                " is outside 2..200");
    if (!(df >= 1.0))  // also rejects NaN
        throw std::domain_error("studentized range: df = " + std::to_string(df) +
                                " must be at least 1");
}

void check_q(double q) {
    if (!(q >= 0.0))  // also rejects NaN
        throw std::domain_error("studentized range: q must be >= 0");
}

bool df_is_infinite(double df) { return df >= kDfTreatedAsInfinite; }

struct Tails {
    double lower, upper;  // P(Q <= q), P(Q > q)
};

// Sum the upper tail directly unless it is surely above 1e-4: P(Q > q) >= P(S < median /
// q) / 2, so then 1 - (lower tail) has relative accuracy 1e-12.
bool sum_upper_tail(double q, const RangeTable& table, double df) {
    const double s = table.median / q;
    if (s >= 1.0) return false;  // P(S < 1) > 0.4 for any df
    // P(a, x) <= x^a e^-x / Gamma(a + 1) / (1 - x / (a + 1)) for x < a + 1: decides the
    // far tail without Boost, which throws where P underflows at huge a.
    const double a = 0.5 * df, x = a * s * s;
    const double log_bound =
        a * std::log(x) - x - std::lgamma(a + 1.0) - std::log1p(-x / (a + 1.0));
    if (log_bound < std::log(2e-4)) return true;
    return 0.5 * boost::math::gamma_p(a, x) <= 1e-4;
}

Tails tails(double q, int k, double df) {
    if (q == 0.0) return {0.0, 1.0};
    if (std::isinf(q)) return {1.0, 0.0};
    const RangeTable& table = range_table(k);
    if (df_is_infinite(df))
        return {std::exp(table.log_lower(q)), std::exp(table.log_upper(q))};
    if (sum_upper_tail(q, table, df)) {
        const double upper =
            std::min(1.0, std::exp(log_mix(q, table, df, Mix::kUpper, true)));
        return {1.0 - upper, upper};
    }
    const double lower =
        std::min(1.0, std::exp(log_mix(q, table, df, Mix::kLower, false)));
    return {lower, 1.0 - lower};
}

double density(double q, int k, double df) {
    const RangeTable& table = range_table(k);
    if (std::isinf(q)) return 0.0;
    if (df_is_infinite(df)) return std::exp(table.log_density(q));
    if (q == 0.0) {  // only k = 2 has mass near 0: f(0) = E[S] f_R(0)
        if (k != 2) return 0.0;
        const double log_mean_scale = 0.5 * std::log(2.0 / df) +
                                      std::lgamma(0.5 * (df + 1.0)) -
                                      std::lgamma(0.5 * df);
        return std::exp(log_mean_scale + table.log_density(0.0));
    }
    const bool upper = sum_upper_tail(q, table, df);
    return std::exp(log_mix(q, table, df, Mix::kDensity, upper)) / q;
}

// Newton on x = log q for log P(Q > q) = log p (p <= 1/2) or log P(Q <= q) = log(1 - p),
// kept inside a bracket so that it never leaves (0, inf).
double solve_quantile(double upper_p, int k, double df) {
    const bool by_upper = upper_p <= 0.5;
    const double log_target = by_upper ? std::log(upper_p) : std::log(1.0 - upper_p);
    const RangeTable& table = range_table(k);
    auto tails_at = [&](double q, double d) {
        return d == kInfiniteDf
                   ? Tails{std::exp(table.log_lower(q)), std::exp(table.log_upper(q))}
                   : tails(q, k, d);
    };
    // F(x) decreases in x; F' = -q f(q) / P.
    auto residual = [&](const Tails& t) {
        return by_upper ? std::log(t.upper) - log_target : log_target - std::log(t.lower);
    };
    // Start: the df = infinity quantile (bisection on the table), widened for finite df.
    double lo = -30.0, hi = std::log(2.0 * kTableEnd);
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (residual(tails_at(std::exp(mid), kInfiniteDf)) > 0.0 ? lo : hi) = mid;
    }
    double x = 0.5 * (lo + hi);
    if (df_is_infinite(df)) df = kInfiniteDf;
    if (df != kInfiniteDf) {
        const double z2 = 0.5 * std::exp(2.0 * x);
        x += std::log1p((1.0 + z2) / (4.0 * df));
    }
    double bracket_lo = kNegInf, bracket_hi = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < 200; ++iteration) {
        const double q = std::exp(x);
        const Tails t = tails_at(q, df);
        const double f = residual(t);
        if (f == 0.0) return q;
        if (f > 0.0)
            bracket_lo = x;
        else
            bracket_hi = x;
        double step = std::numeric_limits<double>::quiet_NaN();
        if (std::isfinite(f)) {
            const double slope = -q * density(q, k, df) / (by_upper ? t.upper : t.lower);
            if (slope < 0.0) step = -f / slope;
        }
        step = std::clamp(step, -3.0, 3.0);  // NaN stays NaN
        double next = x + step;
        if (!(next > bracket_lo && next < bracket_hi)) {
            if (std::isfinite(bracket_lo) && std::isfinite(bracket_hi))
                next = 0.5 * (bracket_lo + bracket_hi);
            else
                next = std::isfinite(bracket_lo) ? x + 3.0 : x - 3.0;
        }
        // Newton converges quadratically: a step this small leaves rounding noise only.
        if (std::fabs(next - x) <= 1e-13 * std::max(1.0, std::fabs(x)))
            return std::exp(next);
        x = next;
    }
    throw std::domain_error("studentized range: the quantile did not converge");
}

}  // namespace

double studentized_range_cdf(double q, int k, double df) {
    check_arguments(k, df);
    check_q(q);
    return tails(q, k, df).lower;
}

double studentized_range_upper(double q, int k, double df) {
    check_arguments(k, df);
    check_q(q);
    return tails(q, k, df).upper;
}

double studentized_range_density(double q, int k, double df) {
    check_arguments(k, df);
    check_q(q);
    return density(q, k, df);
}

void studentized_range_prepare(int k) {
    check_arguments(k, kInfiniteDf);
    range_table(k);
}

double studentized_range_quantile_upper(double upper_p, int k, double df) {
    check_arguments(k, df);
    if (!(upper_p > 0.0 && upper_p < 1.0))
        throw std::domain_error("studentized range: p must lie strictly between 0 and 1");
    // Tukey HSD asks for the same few quantiles (alpha, .05, .01 at one k and df) again
    // and again: remember the last ones per thread.
    struct Remembered {
        double p, df, q;
        int k;
    };
    thread_local std::array<Remembered, 8> remembered{};
    thread_local std::size_t next_slot = 0;
    for (const Remembered& r : remembered)
        if (r.k == k && r.p == upper_p && r.df == df) return r.q;
    const double q = solve_quantile(upper_p, k, df);
    remembered[next_slot++ % remembered.size()] = {upper_p, df, q, k};
    return q;
}

}  // namespace lucent::analysis
