#pragma once
// The studentized range distribution: Q = (max - min of k iid standard normals) / S, with
// S^2 an independent chi-square over df (df = infinity: S = 1). Used by Tukey's HSD.
//
// U_k(w) = P(range > w) and W_k = 1 - U_k are read from a table per k (piecewise
// Chebyshev series of log W_k(w) - (k-1) log w below the median range and of
// log U_k(w) + w^2/4 above it, built once on first use from quadrature of
//   U_k(w) = k Int phi(z) [Qbar(z)^(k-1) - (Qbar(z) - Qbar(z + w))^(k-1)] dz   (min at
//   z)).
// At finite df, P(Q > q) = Int g(u) U_k(q e^u) du over u = log S, summed by the
// trapezoid rule on a fixed grid whose density values are cached per (df, step). Either
// tail is summed directly (never 1 - cdf where the result is tiny), so both keep their
// digits down to the smallest positive double. Thread-safe and deterministic.
#include <limits>

namespace lucent::analysis {

inline constexpr double kInfiniteDf = std::numeric_limits<double>::infinity();

// Valid arguments: 2 <= k <= 200, df >= 1 (or kInfiniteDf), q >= 0, 0 < p < 1.
// Invalid arguments throw std::domain_error naming the argument.
inline constexpr int kMinRangeGroups = 2;
inline constexpr int kMaxRangeGroups = 200;

// P(Q <= q).
double studentized_range_cdf(double q, int k, double df);
// P(Q > q), computed directly (accurate relative to its size, not only to 1e-16).
double studentized_range_upper(double q, int k, double df);
// The density of Q at q.
double studentized_range_density(double q, int k, double df);
// The q with P(Q > q) = upper_p (the critical value for a test at level upper_p).
double studentized_range_quantile_upper(double upper_p, int k, double df);
// Builds the table for k now (otherwise the first evaluation at k does; ~10 ms).
void studentized_range_prepare(int k);

}  // namespace lucent::analysis
