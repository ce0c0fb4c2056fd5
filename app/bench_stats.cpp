// lucent bench stats: the cost of the analysis on a large study (ANOVA + Tukey HSD +
// Kruskal-Wallis on 10^6 ratings in 10 groups, in process and as a whole `lucent analyze`
// process, against R when Rscript is on the PATH) and of the studentized range
// distribution (evaluations per second on one core, and the per-k table build).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/simulate/simulate.h"
#include "analysis/stats/anova.h"
#include "analysis/stats/kruskal_wallis.h"
#include "analysis/stats/studentized_range.h"
#include "analysis/stats/tukey.h"
#include "app/bench_mixed.h"
#include "app/bench_process.h"
#include "app/bench_results.h"
#include "app/commands.h"

namespace lucent::app {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of this thread: rates on one core, whatever else the machine runs.
double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

using Results = BenchResults;  // every printed number, also written to --csv

void bench_in_process(long ratings, int groups, Results& results) {
    using namespace lucent::analysis;
    // Likert ratings 1..7 with a small effect per group, seeded.
    OneWayData data;
    std::mt19937_64 engine(7);
    std::uniform_int_distribution<int> base(1, 6);
    for (int g = 0; g < groups; ++g) data.groups.push_back({std::to_string(g + 1), {}});
    for (long i = 0; i < ratings; ++i) {
        const int g = static_cast<int>(i % groups);
        data.groups[g].values.push_back(
            base(engine) + (engine() % 10 < static_cast<unsigned>(g % 3) ? 1 : 0));
    }
    std::printf("analysis of %ld ratings in %d groups, in process (one run each)\n",
                ratings, groups);
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
    const std::string tukey_name = "Tukey HSD (" + std::to_string(tukey.pairs.size()) +
                                   " p-values, incl. table build)";
    std::printf("  %-40s %10s %8s\n", "step", "ms", "share");
    for (auto [name, t] : {std::pair<std::string, double>{"one-way ANOVA", t_anova},
                           {tukey_name, t_tukey},
                           {"Kruskal-Wallis", t_kw}}) {
        std::printf("  %-40s %10.2f %7.1f%%\n", name.c_str(), 1e3 * t, 100 * t / total);
        results.add("in_process", name, 1e3 * t, "ms");
    }
    std::printf("  %-40s %10.2f   (%.3g ratings/s)\n", "total", 1e3 * total,
                ratings / total);
    results.add("in_process", "total", 1e3 * total, "ms");
    std::printf("  (F = %.6g, %zu Tukey pairs, H = %.6g)\n", anova.f.value_or(-1),
                tukey.pairs.size(), kw.h.value_or(-1));
}

// `lucent analyze` as a whole process on a simulated long CSV (one question, one factor,
// `groups` levels), and R's read.csv + aov + TukeyHSD + kruskal.test + oneway.test on the
// same file when Rscript is on the PATH (nothing is installed).
int bench_whole_process(long ratings, int groups, int repeat, Results& results) {
    namespace fs = std::filesystem;
    const fs::path dir =
        fs::temp_directory_path() / ("lucent-bench-stats-" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path csv = dir / "ratings.csv";
    analysis::SimulationSpec spec;
    spec.stimuli_per_level = 100;
    spec.participants = static_cast<int>(std::max(1L, ratings / (100L * groups)));
    spec.level_effects.clear();
    for (int g = 0; g < groups; ++g) spec.level_effects.push_back(0.1 * g);
    spec.seed = 7;
    const analysis::LongTable table = analysis::simulate_study(spec);
    {
        std::ofstream out(csv, std::ios::binary);
        analysis::write_long_csv(out, table);
        if (!out) {
            std::fprintf(stderr, "lucent bench stats: cannot write %s\n", csv.c_str());
            return kExitFailure;
        }
    }
    std::printf("whole process on %zu ratings in %d levels (%s)\n", table.rows.size(),
                groups, csv.c_str());
    // The `lucent` users run (it runs analyze itself), not this lucent-full process.
    const fs::path self = fs::read_symlink("/proc/self/exe").parent_path() / "lucent";
    // The runs alternate between lucent and R, so that both see the same load on a
    // shared machine; each column is the median of `repeat` runs.
    const std::vector<std::string> lucent_command{
        self.string(), "analyze", csv.string(), "--out", (dir / "report").string(),
        "--format",    "csv",     "--model",    "anova"};
    const bool have_r = on_path("Rscript");
    const fs::path script = dir / "analysis.R";
    if (have_r)
        std::ofstream(script) << "d <- read.csv(commandArgs(trailingOnly = TRUE)[1])\n"
                                 "d$level <- factor(d$level)\n"
                                 "fit <- aov(rating ~ level, data = d)\n"
                                 "print(summary(fit))\n"
                                 "print(TukeyHSD(fit))\n"
                                 "print(kruskal.test(rating ~ level, data = d))\n"
                                 "print(oneway.test(rating ~ level, data = d))\n";
    const std::vector<std::string> r_command{"Rscript", script.string(), csv.string()};
    std::vector<ProcessCost> lucent_runs, r_runs;
    bool r_failed = false;
    for (int run = 0; run < repeat; ++run) {
        lucent_runs.push_back(run_measured(lucent_command));
        if (!lucent_runs.back().ok) {
            std::fprintf(stderr, "lucent bench stats: lucent analyze failed on %s\n",
                         csv.c_str());
            return kExitFailure;
        }
        if (have_r && !r_failed) {
            r_runs.push_back(run_measured(r_command));
            r_failed = !r_runs.back().ok;
        }
    }
    const ProcessCost t_lucent = median_cost(lucent_runs);
    const ProcessCost t_start = run_measured({self.string(), "analyze", "--help"});
    std::printf("  %-40s %10s %10s   (median of %d runs, alternating)\n", "process",
                "wall s", "CPU s", repeat);
    std::printf("  %-40s %10.3f %10.3f\n", "lucent analyze --format csv", t_lucent.wall_s,
                t_lucent.cpu_s);
    std::printf("  %-40s %10.3f %10.3f\n", "  of which starting lucent (analyze --help)",
                t_start.wall_s, t_start.cpu_s);
    results.add("whole_process", "lucent analyze --format csv (wall)", t_lucent.wall_s,
                "s");
    results.add("whole_process", "lucent analyze --format csv (cpu)", t_lucent.cpu_s,
                "s");
    results.add("whole_process", "lucent analyze --help (cpu)", t_start.cpu_s, "s");
    if (!have_r) {
        std::printf(
            "  R comparison skipped: Rscript is not on the PATH (the bench installs "
            "nothing)\n");
    } else if (r_failed) {
        std::printf("  R comparison failed: Rscript exited with an error\n");
    } else {
        const ProcessCost t_r = median_cost(r_runs);
        std::printf("  %-40s %10.3f %10.3f\n", "R read.csv+aov+TukeyHSD+kruskal+oneway",
                    t_r.wall_s, t_r.cpu_s);
        std::printf("  %-40s %9.1fx %9.1fx\n", "R / lucent", t_r.wall_s / t_lucent.wall_s,
                    t_r.cpu_s / t_lucent.cpu_s);
        results.add("whole_process", "R (wall)", t_r.wall_s, "s");
        results.add("whole_process", "R (cpu)", t_r.cpu_s, "s");
        results.add("whole_process", "R / lucent (wall)", t_r.wall_s / t_lucent.wall_s,
                    "ratio");
        results.add("whole_process", "R / lucent (cpu)", t_r.cpu_s / t_lucent.cpu_s,
                    "ratio");
    }
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    return kExitOk;
}

struct RangeArgs {
    double q;
    int k;
    double df;
};

// q spread log-uniformly over [q_low, q_high] (12 points, cycled).
std::vector<RangeArgs> sweep(int k, double df, double q_low, double q_high) {
    std::vector<RangeArgs> args;
    for (int i = 0; i < 12; ++i)
        args.push_back({q_low * std::pow(q_high / q_low, i / 11.0), k, df});
    return args;
}

void bench_distribution(double seconds, Results& results) {
    using namespace lucent::analysis;
    std::printf(
        "studentized range table build (once per k, on first use; thread CPU time)\n");
    for (int k : {50, 200}) {
        const double start = thread_seconds();
        studentized_range_prepare(k);
        const double t = thread_seconds() - start;
        std::printf("  %-40s %10.2f ms\n", ("k=" + std::to_string(k)).c_str(), 1e3 * t);
        results.add("table_build", "k=" + std::to_string(k), 1e3 * t, "ms");
    }
    struct Row {
        std::string name;
        std::vector<RangeArgs> args;
    };
    std::vector<Row> rows = {
        {"k=10, df=30, q 0.5..8", sweep(10, 30, 0.5, 8)},
        {"k=3, df=inf, q 0.5..8", sweep(3, kInfiniteDf, 0.5, 8)},
        {"k=10, df=999990, q 0.5..8", sweep(10, 999990, 0.5, 8)},
        {"k=100, df=2, q 0.5..8", sweep(100, 2, 0.5, 8)},
        {"k=200, df=1, q 0.5..8", sweep(200, 1, 0.5, 8)},
        {"k=10, df=30, q 8..40 (p to 1e-21)", sweep(10, 30, 8, 40)},
        {"k=2, df=1, q 1e2..1e10", sweep(2, 1, 1e2, 1e10)},
        {"k=100, df=2, q 1e2..1e10", sweep(100, 2, 1e2, 1e10)},
        {"k=200, df=1, q 1e2..1e10", sweep(200, 1, 1e2, 1e10)},
    };
    // Random arguments: k 2..200, df 1..1e4 log-uniform, q 0.1..100 log-uniform, a new
    // df at every call (no cached density nodes to reuse).
    std::mt19937_64 engine(11);
    std::uniform_int_distribution<int> random_k(2, 200);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Row random{"random k 2..200, df 1..1e4, q 0.1..100", {}};
    for (int i = 0; i < 4096; ++i)
        random.args.push_back({0.1 * std::pow(1e3, unit(engine)), random_k(engine),
                               std::pow(1e4, unit(engine))});
    for (const RangeArgs& a : random.args) studentized_range_prepare(a.k);  // not timed
    rows.push_back(std::move(random));

    std::printf("studentized range P(Q > q) evaluations, one core (%.1f CPU s per row)\n",
                seconds);
    std::printf("  %-40s %12s %10s\n", "arguments", "evals/s", "us/eval");
    for (const Row& row : rows) {
        for (const RangeArgs& a : row.args) studentized_range_prepare(a.k);
        long evals = 0;
        double checksum = 0.0;
        const double start = thread_seconds();
        while (thread_seconds() - start < seconds)
            for (const RangeArgs& a : row.args) {
                checksum += studentized_range_upper(a.q, a.k, a.df);
                ++evals;
            }
        const double rate = evals / (thread_seconds() - start);
        std::printf("  %-40s %12.0f %10.2f   (checksum %.6g)\n", row.name.c_str(), rate,
                    1e6 / rate, checksum / evals);
        results.add("evals", row.name, rate, "evals/s");
    }
}

int run_bench_stats(long ratings, int groups, double cdf_seconds, bool whole_process,
                    int repeat, const std::vector<long>& mixed_sizes, int mixed_repeat,
                    const std::string& csv_path) {
    using namespace lucent::analysis;
    if (repeat < 1) {
        std::fprintf(stderr, "lucent bench stats: --repeat: must be at least 1\n");
        return kExitUsage;
    }
    if (ratings < 2L * groups || groups < 2 || groups > kMaxRangeGroups) {
        std::fprintf(stderr,
                     "lucent bench stats: need 2..200 groups and 2+ ratings each\n");
        return kExitUsage;
    }
    for (long size : mixed_sizes)
        if (size < 200 || size > 10000000) {
            std::fprintf(
                stderr,
                "lucent bench stats: --mixed-ratings: %ld is not in [200, 10000000]\n",
                size);
            return kExitUsage;
        }
    Results results;
    bench_in_process(ratings, groups, results);
    if (whole_process) {
        const int status = bench_whole_process(ratings, groups, repeat, results);
        if (status != kExitOk) return status;
    }
    bench_distribution(cdf_seconds, results);
    if (!mixed_sizes.empty()) {
        const int status = bench_mixed_models(mixed_sizes, mixed_repeat, results);
        if (status != kExitOk) return status;
    }
    if (!csv_path.empty() && !results.write_csv(csv_path)) {
        std::fprintf(stderr, "lucent bench stats: cannot write %s\n", csv_path.c_str());
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace

void register_bench_stats(CLI::App& bench, int& exit_code) {
    struct Args {
        long ratings = 1000000;
        int groups = 10;
        double cdf_seconds = 1.0;
        bool no_process = false;
        int repeat = 3;
        std::vector<long> mixed_ratings{10000, 100000};
        int mixed_repeat = 1;
        bool no_mixed = false;
        std::string csv;
    };
    auto args = std::make_shared<Args>();
    auto* cmd = bench.add_subcommand(
        "stats",
        "ANOVA + Tukey + Kruskal-Wallis on 10^6 ratings (in process, as a whole 'lucent "
        "analyze', and R when Rscript is on the PATH); studentized-range rates");
    cmd->add_option("--ratings", args->ratings, "Ratings in the synthetic study")
        ->capture_default_str();
    cmd->add_option("--groups", args->groups, "Groups (levels)")->capture_default_str();
    cmd->add_option("--cdf-seconds", args->cdf_seconds,
                    "Seconds per distribution timing row")
        ->capture_default_str();
    cmd->add_option("--repeat", args->repeat,
                    "Whole-process runs of lucent and of R, alternating; the median is "
                    "reported")
        ->capture_default_str();
    cmd->add_flag("--no-process", args->no_process,
                  "Skip the whole-process 'lucent analyze' (and R) timing");
    cmd->add_option("--mixed-ratings", args->mixed_ratings,
                    "Study sizes for the mixed models' whole-process comparison with R "
                    "(lucent analyze --model lmm|clmm), e.g. 10000,100000")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--mixed-repeat", args->mixed_repeat,
                    "Runs of each mixed-model process (median reported)")
        ->capture_default_str();
    cmd->add_flag("--no-mixed", args->no_mixed, "Skip the mixed models");
    cmd->add_option(
        "--csv", args->csv,
        "Also write every timing as CSV (section,name,value,unit) to this file");
    cmd->callback([args, &exit_code] {
        exit_code = run_bench_stats(
            args->ratings, args->groups, args->cdf_seconds, !args->no_process,
            args->repeat, args->no_mixed ? std::vector<long>{} : args->mixed_ratings,
            std::max(1, args->mixed_repeat), args->csv);
    });
}

}  // namespace lucent::app
