#pragma once
// An independent evaluation of the studentized range distribution for the tests: it
// conditions on the *minimum* of the k normals (the library conditions on the maximum),
// integrates with the plain trapezoid rule on a fine grid (exponentially convergent for
// these smooth, fast-decaying integrands) instead of Gauss-Kronrod, mixes over
// t = log(S) instead of S, and works in x87 extended precision (long double).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace lucent::test {

struct RangeProbabilities {
    long double lower;  // P(Q <= q)
    long double upper;  // P(Q > q), computed directly
};

namespace detail {

inline long double phi_upper(long double x) {
    return 0.5L * std::erfc(x / std::sqrt(2.0L));
}
inline long double phi_pdf(long double x) {
    return std::exp(-0.5L * x * x) /
           std::sqrt(2.0L * 3.14159265358979323846264338327950288L);
}

// Trapezoid rule on [a, b] with at most `step` between nodes, for a pair of integrands
// evaluated together (f returns both).
inline RangeProbabilities trapezoid(
    const std::function<RangeProbabilities(long double)>& f, long double a, long double b,
    long double step) {
    const long n = std::max(2L, static_cast<long>(std::ceil((b - a) / step)));
    const long double h = (b - a) / n;
    RangeProbabilities sum{0, 0};
    for (long i = 0; i <= n; ++i) {
        const long double weight = (i == 0 || i == n) ? 0.5L : 1.0L;
        const RangeProbabilities value = f(a + h * i);
        sum.lower += weight * value.lower;
        sum.upper += weight * value.upper;
    }
    return {sum.lower * h, sum.upper * h};
}

// df = infinity, conditioning on the minimum z: the others lie in [z, z + q].
inline RangeProbabilities range_infinite_df(long double q, int k) {
    const int m = k - 1;
    if (q <= 0) return {0.0L, 1.0L};
    auto both = [&](long double z) -> RangeProbabilities {
        const long double above_min = phi_upper(z);
        if (above_min <= 0) return {0, 0};
        const long double above_range = phi_upper(z + q);
        const long double inside = above_min - above_range;
        const long double density = k * phi_pdf(z);
        return {inside <= 0 ? 0.0L : density * std::pow(inside, (long double)m),
                density * std::pow(above_min, (long double)m) *
                    -std::expm1(m * std::log1p(-above_range / above_min))};
    };
    // The narrowest integrand (tiny q: phi(z)^k) has a width near 1/sqrt(k); the
    // trapezoid error falls like exp(-2 pi^2 (width / step)^2).
    const long double step = std::min(0.1L, 0.5L / std::sqrt((long double)k));
    const long double log_k = std::log((long double)k);
    const long double a = -0.5L * q - 12.0L - log_k;
    if (q <= 48) return trapezoid(both, a, 12.0L, step);
    // A large range: the lower integrand lives where the minimum of k normals does, the
    // upper one near z = -q/2 (it falls like e^(-d^2) a distance d away), so each gets
    // its own stretch.
    return {trapezoid(both, -12.0L - log_k, 12.0L, step).lower,
            trapezoid(both, a, -0.5L * q + 12.0L, step).upper};
}

// Finds [lo, hi] where a concave log-density L(t) lies within `drop` of its maximum.
inline void concave_support(const std::function<long double(long double)>& log_density,
                            long double& lo, long double& hi, long double drop) {
    long double a = -80, b = 20;
    for (int i = 0; i < 200; ++i) {  // ternary search for the peak
        const long double m1 = a + (b - a) / 3, m2 = b - (b - a) / 3;
        if (log_density(m1) < log_density(m2))
            a = m1;
        else
            b = m2;
    }
    const long double peak = 0.5L * (a + b), top = log_density(peak);
    auto solve = [&](long double inside, long double outside) {
        for (int i = 0; i < 200; ++i) {
            const long double mid = 0.5L * (inside + outside);
            (log_density(mid) > top - drop ? inside : outside) = mid;
        }
        return outside;
    };
    lo = std::min(lo, solve(peak, -80.0L));
    hi = std::max(hi, solve(peak, 20.0L));
}

}  // namespace detail

// P(Q <= q) and P(Q > q) for k groups and df degrees of freedom (infinity allowed).
inline RangeProbabilities reference_studentized_range(long double q, int k,
                                                      long double df) {
    using namespace detail;
    if (std::isinf(df)) return range_infinite_df(q, k);
    // Log-density of t = log S: S^df exp(-df S^2 / 2) up to a constant.
    const long double log_norm =
        std::log(2.0L) + 0.5L * df * std::log(0.5L * df) - std::lgamma(0.5L * df);
    auto log_density = [&](long double t) {
        return log_norm + df * t - 0.5L * df * std::exp(2 * t);
    };
    // Cover the chi mass, the upper tail's peak (S small: Q ~ exp(-(q S)^2/4)) and the
    // tiny lower tail's peak (W ~ (q S)^(k-1)).
    long double lo = 0, hi = 0;
    concave_support(log_density, lo, hi, 40);
    concave_support(
        [&](long double t) { return log_density(t) - 0.25L * q * q * std::exp(2 * t); },
        lo, hi, 40);
    concave_support([&](long double t) { return log_density(t) + (k - 1) * t; }, lo, hi,
                    40);
    // Narrowest peak: the tiny lower tail's, with curvature 2 (df + k - 1) in t.
    const long double sd = 1.0L / std::sqrt(2.0L * (df + k - 1));
    // Trapezoid error ~ exp(-2 pi^2 (sd / step)^2) = e^-50 at this step.
    const long double step = std::min(0.1L, sd / 1.6L);
    // P(range <= w) <= k (w phi(0))^(k-1) (every other normal within w of the minimum):
    // below 1e-40 the inner integrals are 0 and 1 to far beyond double precision, unless
    // the lower tail itself is tiny. It is not when P(range <= q) > 1e-25, since then
    // P(Q <= q) >= P(S >= 1) P(range <= q) > 1e-26.
    const long double log_phi0 =
        -0.5L * std::log(2.0L * 3.14159265358979323846264338327950288L);
    const bool may_skip = range_infinite_df(q, k).lower > 1e-25L;
    auto both = [&](long double t) -> RangeProbabilities {
        const long double density = std::exp(log_density(t));
        const long double w = q * std::exp(t);
        if (may_skip &&
            std::log((long double)k) + (k - 1) * (std::log(w) + log_phi0) < -92.0L)
            return {0.0L, density};
        const RangeProbabilities inner = range_infinite_df(w, k);
        return {density * inner.lower, density * inner.upper};
    };
    return trapezoid(both, lo, hi, step);
}

}  // namespace lucent::test
