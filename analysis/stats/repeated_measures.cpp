#include "analysis/stats/repeated_measures.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <numeric>

#include "analysis/stats/summation.h"

namespace lucent::analysis {
namespace {

using boost::math::cdf;
using boost::math::complement;

double f_upper(double f, double df1, double df2) {
    if (std::isinf(f)) return 0.0;
    return cdf(complement(boost::math::fisher_f(df1, df2), f));
}

double chi_sq_upper(double x, double df) {
    // A chi-square with 0 df is a point mass at 0 (R: pchisq(0, 0, lower = FALSE) = 0).
    if (df <= 0.0) return 0.0;
    return cdf(complement(boost::math::chi_squared(df), std::max(0.0, x)));
}

// log|det A| of a symmetric positive semi-definite matrix by Cholesky in long double;
// empty when A is not positive definite (singular: fewer participants than contrasts).
std::optional<double> log_det_positive_definite(std::vector<long double> a,
                                                std::size_t n) {
    long double log_det = 0.0L;
    for (std::size_t j = 0; j < n; ++j) {
        long double d = a[j * n + j];
        for (std::size_t k = 0; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
        // Relative to the diagonal: rounding leaves ~1e-19 where the true pivot is 0.
        if (!(d > 1e-14L * std::fabs(a[j * n + j])) || !(d > 0.0L)) return std::nullopt;
        const long double l = std::sqrt(d);
        a[j * n + j] = l;
        log_det += 2.0L * std::log(l);
        for (std::size_t i = j + 1; i < n; ++i) {
            long double s = a[i * n + j];
            for (std::size_t k = 0; k < j; ++k) s -= a[i * n + k] * a[j * n + k];
            a[i * n + j] = s / l;
        }
    }
    return static_cast<double>(log_det);
}

std::string with_reason(std::string note, const std::string& reason) {
    return note.empty() ? reason : note + "; " + reason;
}

// Mean of each column and row, and the grand mean, in long double: the decomposition's
// residuals y - row - column + grand are then accurate to about one rounding.
struct Margins {
    std::vector<long double> row, column;
    long double grand = 0.0L;
};
Margins margins(const SubjectByLevel& d) {
    const std::size_t n = d.rows(), k = d.columns();
    Margins m{std::vector<long double>(n, 0.0L), std::vector<long double>(k, 0.0L), 0.0L};
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < k; ++j) {
            m.row[i] += d.value(i, j);
            m.column[j] += d.value(i, j);
        }
    for (auto& r : m.row) {
        m.grand += r;
        r /= static_cast<long double>(k);
    }
    for (auto& c : m.column) c /= static_cast<long double>(n);
    m.grand /= static_cast<long double>(n * k);
    return m;
}

}  // namespace

RepeatedMeasuresAnova repeated_measures_anova(const SubjectByLevel& d) {
    RepeatedMeasuresAnova r;
    const std::size_t n = d.rows(), k = d.columns();
    r.participants = static_cast<int>(n);
    r.levels = static_cast<int>(k);
    if (k < 2) {
        r.note = "needs at least two levels";
        return r;
    }
    if (n < 2) {
        r.note = "needs at least two participants who rated every level";
        return r;
    }
    const Margins m = margins(d);
    long double ss_effect = 0, ss_participants = 0, ss_error = 0;
    for (std::size_t j = 0; j < k; ++j)
        ss_effect += (m.column[j] - m.grand) * (m.column[j] - m.grand);
    for (std::size_t i = 0; i < n; ++i)
        ss_participants += (m.row[i] - m.grand) * (m.row[i] - m.grand);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < k; ++j) {
            const long double e = d.value(i, j) - m.row[i] - m.column[j] + m.grand;
            ss_error += e * e;
        }
    // Residuals below what rounding of the double inputs can produce (amplitudes under
    // ~64 ulp of the data's spread) are zero: additive data give F = inf, not 1e300.
    const long double noise = 64.0L * std::numeric_limits<double>::epsilon();
    const long double ss_total = ss_effect * n + ss_participants * k + ss_error;
    if (ss_error <= noise * noise * ss_total) ss_error = 0.0L;
    r.ss_effect = static_cast<double>(ss_effect * n);
    r.ss_participants = static_cast<double>(ss_participants * k);
    r.ss_error = static_cast<double>(ss_error);
    r.df_effect = static_cast<double>(k - 1);
    r.df_error = static_cast<double>((n - 1) * (k - 1));

    if (r.ss_effect + r.ss_error > 0.0) {
        r.partial_eta_sq = r.ss_effect / (r.ss_effect + r.ss_error);
        r.generalized_eta_sq =
            r.ss_effect / (r.ss_effect + r.ss_participants + r.ss_error);
    }
    if (r.ss_error > 0.0) {
        r.f = (r.ss_effect / r.df_effect) / (r.ss_error / r.df_error);
        r.p = f_upper(*r.f, r.df_effect, r.df_error);
    } else if (r.ss_effect > 0.0) {
        r.f = std::numeric_limits<double>::infinity();
        r.p = 0.0;
        r.note = "no residual variance: every participant shifts the levels alike";
    } else {
        r.note = "no variation between levels nor residual: F is undefined";
    }

    // Sphericity on orthonormal (Helmert) contrasts z = C'y: the statistics depend only
    // on the space the contrasts span (R's T = Thin.row(proj(M) - proj(X)) with X = ~1
    // gives the same W and epsilons). B is their sums of squares and products.
    const std::size_t pp = k - 1;
    std::vector<long double> z(n * pp), mean(pp, 0.0L);
    for (std::size_t c = 0; c < pp; ++c) {
        const long double scale =
            1.0L / std::sqrt(static_cast<long double>((c + 1) * (c + 2)));
        for (std::size_t i = 0; i < n; ++i) {
            long double s = 0.0L;
            for (std::size_t j = 0; j <= c; ++j) s += d.value(i, j);
            s -= static_cast<long double>(c + 1) * d.value(i, c + 1);
            z[i * pp + c] = s * scale;
            mean[c] += z[i * pp + c];
        }
        mean[c] /= static_cast<long double>(n);
    }
    std::vector<long double> b(pp * pp, 0.0L);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t a = 0; a < pp; ++a)
            for (std::size_t c = 0; c <= a; ++c)
                b[a * pp + c] += (z[i * pp + a] - mean[a]) * (z[i * pp + c] - mean[c]);
    long double trace = 0.0L, trace_sq = 0.0L;
    for (std::size_t a = 0; a < pp; ++a) {
        for (std::size_t c = 0; c < a; ++c) {
            b[c * pp + a] = b[a * pp + c];
            trace_sq += 2.0L * b[a * pp + c] * b[a * pp + c];
        }
        trace += b[a * pp + a];
        trace_sq += b[a * pp + a] * b[a * pp + a];
    }
    if (!(trace > noise * noise * ss_total)) {
        r.note = with_reason(r.note,
                             "the level differences have zero variance: no "
                             "sphericity test or correction");
        return r;
    }
    const double gg =
        static_cast<double>(trace * trace / (trace_sq * static_cast<long double>(pp)));
    r.gg_epsilon = gg;
    const double big_n = static_cast<double>(n), dp = static_cast<double>(pp);
    const double hf_den = dp * (big_n - 1.0 - dp * gg);
    if (hf_den > 0.0 && big_n * dp * gg - 2.0 > 0.0) {
        r.hf_epsilon = (big_n * dp * gg - 2.0) / hf_den;
    } else {
        r.note = with_reason(r.note, "too few participants for the Huynh-Feldt epsilon");
    }
    if (r.f) {
        r.p_gg = f_upper(*r.f, r.df_effect * gg, r.df_error * gg);
        if (r.hf_epsilon) {
            const double hf = std::min(1.0, *r.hf_epsilon);
            r.p_hf = f_upper(*r.f, r.df_effect * hf, r.df_error * hf);
        }
    }

    if (pp == 1) {
        // One contrast: sphericity holds by construction (W = 1); R's chi-square with
        // 0 df would print p = 0, which reads as a violation.
        r.mauchly_w = 1.0;
        r.note =
            with_reason(r.note, "two levels: sphericity holds trivially, no Mauchly p");
        return r;
    }
    if (n - 1 < pp) {
        r.note = with_reason(
            r.note, "Mauchly's test needs at least as many participants as levels");
        return r;
    }
    const std::optional<double> log_det = log_det_positive_definite(b, pp);
    if (!log_det) {
        r.note =
            with_reason(r.note, "the contrasts' covariance is singular: no Mauchly test");
        return r;
    }
    const double log_w = *log_det - dp * std::log(static_cast<double>(trace) / dp);
    r.mauchly_w = std::exp(std::min(0.0, log_w));
    // R's mauchly.test.SSD, second-order term included (with its 3 * p, p = levels).
    const double df = big_n - 1.0, levels = static_cast<double>(k);
    const double rho = 1.0 - (2.0 * dp * dp + dp + 2.0) / (6.0 * dp * df);
    const double w2 = (dp + 2.0) * (dp - 1.0) * (dp - 2.0) *
                      (2.0 * dp * dp * dp + 6.0 * dp * dp + 3.0 * levels + 2.0) /
                      (288.0 * (df * dp * rho) * (df * dp * rho));
    const double chi = -df * rho * log_w;
    const double f_df = dp * (dp + 1.0) / 2.0 - 1.0;
    const double pr1 = chi_sq_upper(chi, f_df), pr2 = chi_sq_upper(chi, f_df + 4.0);
    r.mauchly_p = std::clamp(pr1 + w2 * (pr2 - pr1), 0.0, 1.0);
    return r;
}

FriedmanResult friedman_test(const SubjectByLevel& d) {
    FriedmanResult r;
    const std::size_t n = d.rows(), k = d.columns();
    r.participants = static_cast<int>(n);
    if (k < 2 || n < 2) {
        r.note = k < 2 ? "needs at least two levels"
                       : "needs at least two participants who rated every level";
        return r;
    }
    std::vector<double> rank_sums(k, 0.0);
    double ties = 0.0;
    std::vector<std::size_t> order(k);
    for (std::size_t i = 0; i < n; ++i) {
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
            return d.value(i, a) < d.value(i, b);
        });
        for (std::size_t a = 0; a < k;) {
            std::size_t b = a;
            while (b < k && d.value(i, order[b]) == d.value(i, order[a])) ++b;
            const double mid_rank = 0.5 * static_cast<double>(a + 1 + b);
            const double t = static_cast<double>(b - a);
            ties += t * t * t - t;
            for (std::size_t m = a; m < b; ++m) rank_sums[order[m]] += mid_rank;
            a = b;
        }
    }
    const double dn = static_cast<double>(n), dk = static_cast<double>(k);
    const double denominator = dn * dk * (dk + 1.0) - ties / (dk - 1.0);
    r.df = dk - 1.0;
    if (!(denominator > 0.0)) {
        r.note = "every participant gave every level the same value: no ranks to test";
        return r;
    }
    CompensatedSum spread;
    for (double rs : rank_sums) {
        const double dev = rs - dn * (dk + 1.0) / 2.0;
        spread.add(dev * dev);
    }
    r.chi_sq = std::max(0.0, 12.0 * spread.value() / denominator);
    r.p = chi_sq_upper(*r.chi_sq, *r.df);
    r.kendall_w = std::min(1.0, *r.chi_sq / (dn * (dk - 1.0)));
    return r;
}

std::vector<Statistic> holm_adjust(const std::vector<Statistic>& p) {
    std::vector<std::size_t> defined;
    for (std::size_t i = 0; i < p.size(); ++i)
        if (p[i]) defined.push_back(i);
    std::stable_sort(defined.begin(), defined.end(),
                     [&](std::size_t a, std::size_t b) { return *p[a] < *p[b]; });
    std::vector<Statistic> adjusted(p.size());
    const double m = static_cast<double>(defined.size());
    double running_max = 0.0;
    for (std::size_t rank = 0; rank < defined.size(); ++rank) {
        running_max =
            std::max(running_max, (m - static_cast<double>(rank)) * *p[defined[rank]]);
        adjusted[defined[rank]] = std::min(1.0, running_max);
    }
    return adjusted;
}

std::vector<PairedComparison> paired_t_tests_holm(const SubjectByLevel& d) {
    std::vector<PairedComparison> pairs;
    const std::size_t n = d.rows(), k = d.columns();
    for (std::size_t a = 0; a < k; ++a)
        for (std::size_t b = a + 1; b < k; ++b) {
            PairedComparison c{d.levels[a], d.levels[b], {}, {}, {}, {}, {}, ""};
            if (n < 2) {
                c.note = "needs at least two participants who rated both levels";
                pairs.push_back(c);
                continue;
            }
            long double sum = 0.0L;
            for (std::size_t i = 0; i < n; ++i) sum += d.value(i, b) - d.value(i, a);
            const long double mean = sum / static_cast<long double>(n);
            long double squares = 0.0L;
            for (std::size_t i = 0; i < n; ++i) {
                const long double e = (d.value(i, b) - d.value(i, a)) - mean;
                squares += e * e;
            }
            c.diff = static_cast<double>(mean);
            c.df = static_cast<double>(n - 1);
            const double se = static_cast<double>(std::sqrt(
                squares / static_cast<long double>(n - 1) / static_cast<long double>(n)));
            // R's t.test: "data are essentially constant" below 10 eps of the mean.
            if (!(se >
                  10.0 * std::numeric_limits<double>::epsilon() * std::fabs(*c.diff))) {
                c.note = "the differences have zero variance: t is undefined";
            } else {
                c.t = *c.diff / se;
                c.p = 2.0 *
                      cdf(complement(boost::math::students_t(*c.df), std::fabs(*c.t)));
                c.p = std::min(1.0, *c.p);
            }
            pairs.push_back(c);
        }
    std::vector<Statistic> p;
    for (const PairedComparison& c : pairs) p.push_back(c.p);
    const std::vector<Statistic> adjusted = holm_adjust(p);
    for (std::size_t i = 0; i < pairs.size(); ++i) pairs[i].p_holm = adjusted[i];
    return pairs;
}

}  // namespace lucent::analysis
