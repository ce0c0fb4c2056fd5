// Studentized range distribution on Boost.Math: normal tails through erfc, chi density
// through gamma_p_derivative, adaptive Gauss-Kronrod quadrature, TOMS 748 root finding.
#include "stats/studentized_range.h"

#include <algorithm>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/erf.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <queue>
#include <stdexcept>
#include <string>
#include <vector>

namespace lucent::analysis {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr double kInvSqrt2Pi = 0.39894228040143267794;
// Above this df the chi density is so narrow that df = infinity is exact to ~1/df.
constexpr double kDfTreatedAsInfinite = 1e12;
// Half-width of every integration range in standard deviations of its integrand's peak
// (exp(-14^2/2) ~ 1e-43: what lies beyond is below any representable tail we report).
constexpr double kHalfWidthSds = 14.0;

double normal_cdf(double x) { return 0.5 * std::erfc(-x * kInvSqrt2); }
double normal_upper(double x) { return 0.5 * std::erfc(x * kInvSqrt2); }
double normal_pdf(double x) { return kInvSqrt2Pi * std::exp(-0.5 * x * x); }

// P(a < Z <= b) without cancellation: a short interval is integrated directly
// (10-point Gauss-Legendre is exact to rounding on a width below 1); otherwise the
// difference is taken in whichever tail the interval lies.
double normal_mass(double a, double b) {
    if (b - a < 1.0)
        return boost::math::quadrature::gauss<double, 10>::integrate(normal_pdf, a, b);
    return a + b >= 0.0 ? normal_upper(a) - normal_upper(b) : normal_cdf(b) - normal_cdf(a);
}

// Integrates f over the pieces between sorted breakpoints with globally adaptive
// 21-point Gauss-Kronrod (QUADPACK's QAG strategy): the piece with the largest error
// estimate is halved until the summed estimate falls below relative_tolerance * |sum|.
// Judging every piece against the whole integral keeps negligible pieces cheap.
template <unsigned Points = 21, class F>
double integrate_pieces(F f, std::vector<double> points, double relative_tolerance) {
    using Rule = boost::math::quadrature::gauss_kronrod<double, Points>;
    struct Piece {
        double a, b, value, error;
        bool operator<(const Piece& other) const { return error < other.error; }
    };
    std::sort(points.begin(), points.end());
    std::priority_queue<Piece> pieces;
    double sum = 0.0, error = 0.0;
    auto add = [&](double a, double b) {
        // Boost returns |Kronrod - Gauss| on [-1, 1]; scale it to [a, b] and sharpen it
        // as QUADPACK does (the Kronrod result is far better than that difference).
        double raw_error = 0.0, l1 = 0.0;
        const double value = Rule::integrate(f, a, b, 0, 0.0, &raw_error, &l1);
        const double difference = raw_error * 0.5 * (b - a);
        const double piece_error =
            l1 > 0.0 ? l1 * std::min(1.0, std::pow(200.0 * difference / l1, 1.5)) : 0.0;
        pieces.push({a, b, value, piece_error});
        sum += value;
        error += piece_error;
    };
    for (std::size_t i = 0; i + 1 < points.size(); ++i)
        if (points[i + 1] > points[i]) add(points[i], points[i + 1]);
    constexpr int kMaxSplits = 400;  // ~17k evaluations: far more than smooth pieces need
    for (int split = 0; split < kMaxSplits && !pieces.empty(); ++split) {
        if (error <= relative_tolerance * std::fabs(sum)) break;
        const Piece worst = pieces.top();
        pieces.pop();
        sum -= worst.value;
        error -= worst.error;
        const double mid = 0.5 * (worst.a + worst.b);
        add(worst.a, mid);
        add(mid, worst.b);
    }
    // Re-add the pieces exactly: the running sum has absorbed subtractions.
    double total = 0.0;
    for (; !pieces.empty(); pieces.pop()) total += pieces.top().value;
    return total;
}

// Breakpoints every `step` from a to b (so no peak hides between the first nodes).
std::vector<double> even_points(double a, double b, double step) {
    std::vector<double> points;
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a) / step)));
    for (int i = 0; i <= pieces; ++i) points.push_back(a + (b - a) * i / pieces);
    return points;
}

// P(range of k standard normals <= q): condition on the maximum z; all others lie in
// [z - q, z]. The difference of Phi values is taken on whichever side avoids cancellation.
double range_cdf_infinite_df(double q, int k) {
    if (q <= 0.0) return 0.0;
    const int m = k - 1;
    auto integrand = [q, k, m](double z) {
        const double inside = normal_mass(z - q, z);
        if (inside <= 0.0) return 0.0;
        return k * normal_pdf(z) * std::pow(inside, m);
    };
    // The maximum of k normals lies above Phi^-1(1e-22^(1/m)) except with probability
    // 1e-22, and below 9.5 + log(k) / 9.5 likewise; with a tiny q it sits near q / 2.
    const double lowest = -std::sqrt(2.0 * std::log(1e22) / m) - 1.0;
    const double low = std::max(-9.5, std::min(lowest, 0.5 * q - 9.5));
    const double high = std::min(9.5 + std::log(double(k)) / 9.5, 0.5 * q + 9.5);
    auto points = even_points(low, std::max(high, low + 1.0), 5.0);
    return std::min(1.0, integrate_pieces(integrand, points, 1e-12));
}

// P(range of k standard normals > q) = k Int phi(z) [Phi(z)^m - (Phi(z) - Phi(z-q))^m] dz,
// with a^m - (a - c)^m = a^m * -expm1(m log1p(-c / a)) so tiny tails keep their digits.
double range_upper_infinite_df(double q, int k) {
    if (q <= 0.0) return 1.0;
    const int m = k - 1;
    auto integrand = [q, k, m](double z) {
        const double below_max = normal_cdf(z);
        if (below_max <= 0.0) return 0.0;
        const double below_range = normal_cdf(z - q);
        const double spread = -std::expm1(m * std::log1p(-below_range / below_max));
        return k * normal_pdf(z) * std::pow(below_max, m) * spread;
    };
    // For large q the mass sits near z = q/2 (max at +q/2, min at -q/2), width ~ 1/sqrt2.
    const double low = std::max(-9.5, 0.5 * q - 9.5 - std::log(double(k)));
    const double high = 0.5 * q + 9.5 + std::log(double(k));
    auto points = even_points(low, high, 5.0);
    return std::min(1.0, integrate_pieces(integrand, points, 1e-12));
}

// Density of S = sqrt(chi2_df / df): d/ds P(df/2, df s^2 / 2).
double scale_density(double s, double df) {
    if (s <= 0.0) return 0.0;
    return boost::math::gamma_p_derivative(0.5 * df, 0.5 * df * s * s) * df * s;
}

// Integrates g_df(s) * inner(q s) over the scale S, with breakpoints where the integrand
// can change quickly: the chi mode, where q s crosses typical ranges, and where the
// tail's integrand peaks (S small enough that even q s is an ordinary range).
template <class Inner>
double mix_over_scale(double q, int k, double df, Inner inner, bool upper) {
    const double sd = 1.0 / std::sqrt(2.0 * df);
    const double mode = std::sqrt(std::max(0.0, (df - 1.0) / df));
    const double m = k - 1.0;
    // Peak of g(s) * exp(-(q s)^2 / 4) (the upper tail) and of g(s) (q s)^m (tiny lower).
    const double tail_peak = std::sqrt(std::max(0.0, (df - 1.0) / (df + 0.5 * q * q)));
    const double tail_sd = 1.0 / std::sqrt(2.0 * df + q * q);
    const double lower_peak = std::sqrt((df - 1.0 + m) / df);
    double low = mode - kHalfWidthSds * sd;
    double high = mode + kHalfWidthSds * sd;
    if (upper) low = std::min(low, tail_peak - kHalfWidthSds * tail_sd);
    else high = std::max(high, lower_peak + kHalfWidthSds * sd);
    low = std::max(0.0, low);

    std::vector<double> points{low, high};
    auto add = [&](double s) {
        if (s > low && s < high) points.push_back(s);
    };
    add(mode);
    add(upper ? tail_peak : lower_peak);
    // Typical ranges of k normals run from about 1 to 6: mark where q s crosses them.
    if (q > 0.0)
        for (double typical : {1.0, 4.0}) add(typical / q);
    auto integrand = [&](double s) {
        const double density = scale_density(s, df);
        return density == 0.0 ? 0.0 : density * inner(q * s, k);
    };
    return std::min(1.0, integrate_pieces(integrand, points, 1e-11));
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

}  // namespace

double studentized_range_cdf(double q, int k, double df) {
    check_arguments(k, df);
    check_q(q);
    if (std::isinf(q)) return 1.0;
    if (df_is_infinite(df)) {
        const double lower = range_cdf_infinite_df(q, k);
        return lower < 0.5 ? lower : 1.0 - range_upper_infinite_df(q, k);
    }
    const double lower = mix_over_scale(q, k, df, range_cdf_infinite_df, false);
    if (lower < 0.5) return lower;
    return 1.0 - mix_over_scale(q, k, df, range_upper_infinite_df, true);
}

double studentized_range_upper(double q, int k, double df) {
    check_arguments(k, df);
    check_q(q);
    if (std::isinf(q)) return 0.0;
    const double upper = df_is_infinite(df)
                             ? range_upper_infinite_df(q, k)
                             : mix_over_scale(q, k, df, range_upper_infinite_df, true);
    if (upper < 0.5) return upper;
    const double lower = df_is_infinite(df)
                             ? range_cdf_infinite_df(q, k)
                             : mix_over_scale(q, k, df, range_cdf_infinite_df, false);
    return 1.0 - lower;
}

double studentized_range_quantile_upper(double upper_p, int k, double df) {
    check_arguments(k, df);
    if (!(upper_p > 0.0 && upper_p < 1.0))
        throw std::domain_error("studentized range: p must lie strictly between 0 and 1");
    // Solve on log(P(Q > q)) for small p (relative accuracy) and on the CDF otherwise.
    const bool small = upper_p < 0.5;
    auto residual = [&](double q) {
        if (small) {
            const double upper = studentized_range_upper(q, k, df);
            return upper > 0.0 ? std::log(upper) - std::log(upper_p) : -1e300;
        }
        return (1.0 - upper_p) - studentized_range_cdf(q, k, df);
    };
    // Bracket: q = 0 has upper tail 1; double the upper end until the tail falls below p.
    double low = 0.0, high = 4.0;
    double residual_low = small ? -std::log(upper_p) : 1.0 - upper_p;
    double residual_high = residual(high);
    while (residual_high > 0.0) {
        low = high;
        residual_low = residual_high;
        high *= 2.0;
        if (high > 1e12)
            throw std::domain_error("studentized range: quantile beyond 1e12");
        residual_high = residual(high);
    }
    if (residual_high == 0.0) return high;
    boost::math::tools::eps_tolerance<double> tolerance(48);
    std::uintmax_t iterations = 200;
    auto [a, b] = boost::math::tools::toms748_solve(residual, low, high, residual_low,
                                                    residual_high, tolerance, iterations);
    return 0.5 * (a + b);
}

}  // namespace lucent::analysis
