#pragma once
// The studentized range distribution: Q = (max - min of k iid standard normals) / S, with
// S^2 an independent chi-square over df (df = infinity: S = 1). Used by Tukey's HSD.
//
// Computed by adaptive Gauss-Kronrod quadrature (Boost.Math) of
//   P(Q <= q; k, inf) = k * Int phi(z) [Phi(z) - Phi(z - q)]^(k-1) dz        (max at z)
//   P(Q <= q; k, df)  = Int g_df(s) P(Q <= q s; k, inf) ds                  (s = S)
// The upper tail has its own integrand (never 1 - cdf), so p-values far in the tail keep
// their digits down to the smallest positive double.
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
// The q with P(Q > q) = upper_p (the critical value for a test at level upper_p).
double studentized_range_quantile_upper(double upper_p, int k, double df);

}  // namespace lucent::analysis
