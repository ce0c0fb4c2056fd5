// lucent bench stats: the cost of the analysis on a large study (ANOVA + Tukey HSD +
// Kruskal-Wallis on 10^6 ratings in 10 groups) and of the studentized-range CDF.
#include <chrono>
#include <cstdio>
#include <random>

#include "commands.h"
#include "stats/anova.h"
#include "stats/kruskal_wallis.h"
#include "stats/studentized_range.h"
#include "stats/tukey.h"

namespace lucent::app {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

int run_bench_stats(long ratings, int groups, double cdf_seconds) {
    using namespace lucent::analysis;
    if (ratings < 2L * groups || groups < 2 || groups > kMaxRangeGroups) {
        std::fprintf(stderr, "lucent bench stats: need 2..200 groups and 2+ ratings each\n");
        return kExitUsage;
    }
    // Likert ratings 1..7 with a small effect per group, seeded.
    OneWayData data;
    std::mt19937_64 engine(7);
    std::uniform_int_distribution<int> base(1, 6);
    for (int g = 0; g < groups; ++g) data.groups.push_back({std::to_string(g + 1), {}});
    for (long i = 0; i < ratings; ++i) {
        const int g = static_cast<int>(i % groups);
        data.groups[g].values.push_back(base(engine) + (engine() % 10 < static_cast<unsigned>(g % 3) ? 1 : 0));
    }
    std::printf("analysis of %ld ratings in %d groups (one run each)\n", ratings, groups);
    auto start = Clock::now();
    const AnovaResult anova = one_way_anova(data);
    const double t_anova = seconds_since(start);
    start = Clock::now();
    const TukeyResult tukey = tukey_hsd(data, anova, {0.05, true});
    const double t_tukey = seconds_since(start);
    start = Clock::now();
    const KruskalWallisResult kw = kruskal_wallis(data);
    const double t_kw = seconds_since(start);
    const double total = t_anova + t_tukey + t_kw;
    std::printf("  %-26s %10s %8s\n", "step", "ms", "share");
    std::printf("  %-26s %10.2f %7.1f%%\n", "one-way ANOVA", 1e3 * t_anova, 100 * t_anova / total);
    std::printf("  %-26s %10.2f %7.1f%%\n", "Tukey HSD (45 p-values)", 1e3 * t_tukey,
                100 * t_tukey / total);
    std::printf("  %-26s %10.2f %7.1f%%\n", "Kruskal-Wallis", 1e3 * t_kw, 100 * t_kw / total);
    std::printf("  %-26s %10.2f   (%.3g ratings/s)\n", "total", 1e3 * total, ratings / total);
    std::printf("  (F = %.6g, %zu Tukey pairs, H = %.6g)\n", anova.f.value_or(-1),
                tukey.pairs.size(), kw.h.value_or(-1));

    // Studentized-range CDF over a spread of arguments, finite and infinite df.
    std::printf("studentized-range CDF evaluations (%.1f s per row)\n", cdf_seconds);
    std::printf("  %-28s %12s %10s\n", "arguments", "evals/s", "us/eval");
    struct Row { const char* name; int k; double df; };
    const Row rows[] = {{"k=3, df=inf, q in 0.5..8", 3, kInfiniteDf},
                        {"k=10, df=inf, q in 0.5..8", 10, kInfiniteDf},
                        {"k=3, df=30, q in 0.5..8", 3, 30.0},
                        {"k=10, df=30, q in 0.5..8", 10, 30.0},
                        {"k=10, df=999990, q in 0.5..8", 10, 999990.0},
                        {"k=100, df=2, q in 0.5..8", 100, 2.0}};
    double first_rate = 0.0;
    for (const Row& row : rows) {
        long evals = 0;
        double sink = 0.0;
        start = Clock::now();
        while (seconds_since(start) < cdf_seconds)
            for (double q = 0.5; q <= 8.0; q += 0.75, ++evals)
                sink += studentized_range_cdf(q, row.k, row.df);
        const double rate = evals / seconds_since(start);
        if (first_rate == 0.0) first_rate = rate;
        std::printf("  %-28s %12.0f %10.1f   (x%.3g vs first row; checksum %.3g)\n", row.name,
                    rate, 1e6 / rate, first_rate / rate, sink);
    }
    return kExitOk;
}

}  // namespace

void register_bench_stats(CLI::App& bench, int& exit_code) {
    struct Args { long ratings = 1000000; int groups = 10; double cdf_seconds = 1.0; };
    auto args = std::make_shared<Args>();
    auto* cmd = bench.add_subcommand(
        "stats", "ANOVA + Tukey + Kruskal-Wallis on 10^6 ratings; studentized-range CDF rate");
    cmd->add_option("--ratings", args->ratings, "Ratings in the synthetic study")
        ->capture_default_str();
    cmd->add_option("--groups", args->groups, "Groups (levels)")->capture_default_str();
    cmd->add_option("--cdf-seconds", args->cdf_seconds, "Seconds per CDF timing row")
        ->capture_default_str();
    cmd->callback([args, &exit_code] {
        exit_code = run_bench_stats(args->ratings, args->groups, args->cdf_seconds);
    });
}

}  // namespace lucent::app
