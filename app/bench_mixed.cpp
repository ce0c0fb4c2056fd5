#include "app/bench_mixed.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "analysis/data/long_table.h"
#include "analysis/mixed/model_frame.h"
#include "analysis/simulate/simulate.h"
#include "app/bench_process.h"
#include "app/commands.h"

namespace lucent::app {
namespace {

namespace fs = std::filesystem;

constexpr int kLevels = 4, kStimuliPerLevel = 15, kQuestions = 3;

// The R side: per question, the same model, its test of the level, and the level
// effects, written as question,term,estimate,statistic.
constexpr const char* kRScript =
    R"(suppressMessages({library(lme4); library(lmerTest); library(ordinal)})
a <- commandArgs(trailingOnly = TRUE)
d <- read.csv(a[1]); model <- a[3]; rows <- list()
for (q in unique(d$question)) {
  s <- d[d$question == q, ]
  s$level <- factor(s$level); s$participant <- factor(s$participant); s$stimulus <- factor(s$stimulus)
  if (model == "lmm") {
    m <- lmer(rating ~ level + (1 | participant) + (1 | stimulus), s)
    m0 <- lmer(rating ~ 1 + (1 | participant) + (1 | stimulus), s)
    statistic <- anova(m)$`F value`[1]
    invisible(anova(m0, m))
    est <- fixef(m)[-1]
  } else {
    s$rating <- factor(s$rating, ordered = TRUE)
    m <- clmm(rating ~ level + (1 | participant) + (1 | stimulus), s)
    m0 <- clmm(rating ~ 1 + (1 | participant) + (1 | stimulus), s)
    statistic <- anova(m0, m)$LR.stat[2]
    est <- coef(m)[grepl("^level", names(coef(m)))]
  }
  rows[[q]] <- data.frame(question = q, term = names(est), estimate = unname(est),
                          statistic = statistic)
}
write.csv(do.call(rbind, rows), a[2], row.names = FALSE)
)";

analysis::SimulationSpec design_of(long ratings) {
    analysis::SimulationSpec spec;
    spec.questions = {"translucent", "realistic", "glossy"};
    spec.factor = "level";
    spec.level_effects = {0.0, 0.2, 0.4, 0.6};
    spec.stimuli_per_level = kStimuliPerLevel;
    spec.participants = int(std::max(
        2L, std::lround(double(ratings) / (kLevels * kStimuliPerLevel * kQuestions))));
    spec.participant_sd = 0.6;
    spec.stimulus_sd = 0.4;
    spec.noise_sd = 1.0;
    spec.seed = 7;
    return spec;
}

// (question, level) -> (estimate, statistic) from Lucent's report or R's table.
using Estimates =
    std::map<std::pair<std::string, std::string>, std::pair<double, double>>;

Estimates lucent_estimates(const fs::path& report) {
    Estimates estimates;
    const auto effects =
        analysis::mixed::DataFrame::read_csv(report / "mixed_effects.csv");
    const auto tests = analysis::mixed::DataFrame::read_csv(report / "mixed_tests.csv");
    std::map<std::string, double> statistic;
    for (std::size_t i = 0; i < tests.rows(); ++i)
        statistic[tests.text("question")[i]] = std::stod(tests.text("statistic")[i]);
    for (std::size_t i = 0; i < effects.rows(); ++i) {
        const std::string question = effects.text("question")[i];
        estimates[{question, "level" + effects.text("level")[i]}] = {
            std::stod(effects.text("estimate")[i]), statistic[question]};
    }
    return estimates;
}

Estimates r_estimates(const fs::path& table) {
    Estimates estimates;
    const auto frame = analysis::mixed::DataFrame::read_csv(table);
    const auto estimate = frame.numeric("estimate"),
               statistic = frame.numeric("statistic");
    for (std::size_t i = 0; i < frame.rows(); ++i)
        estimates[{frame.text("question")[i], frame.text("term")[i]}] = {estimate[i],
                                                                         statistic[i]};
    return estimates;
}

// The largest relative difference of the level effects and of the tests' statistics.
std::pair<double, double> largest_differences(const Estimates& a, const Estimates& b) {
    double effects = 0.0, statistics = 0.0;
    for (const auto& [key, value] : a) {
        const auto other = b.find(key);
        if (other == b.end()) return {HUGE_VAL, HUGE_VAL};
        auto relative = [](double x, double y) {
            return std::abs(x - y) / std::max(1e-3, std::abs(y));
        };
        effects = std::max(effects, relative(value.first, other->second.first));
        statistics = std::max(statistics, relative(value.second, other->second.second));
    }
    return {effects, statistics};
}

void print_cost(const char* who, const ProcessCost& cost) {
    std::printf("    %-10s %9.2f %9.2f %9.0f\n", who, cost.wall_s, cost.cpu_s,
                cost.peak_mib);
}

}  // namespace

int bench_mixed_models(const std::vector<long>& sizes, int repeat,
                       BenchResults& results) {
    const fs::path dir =
        fs::temp_directory_path() / ("lucent-bench-mixed-" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path self = fs::read_symlink("/proc/self/exe").parent_path() / "lucent";
    const bool have_r = on_path("Rscript");
    std::ofstream(dir / "models.R") << kRScript;
    std::printf(
        "mixed models as whole processes: lucent analyze --model M against R on the "
        "same CSV (%d levels x %d stimuli, %d questions; median of %d runs)\n",
        kLevels, kStimuliPerLevel, kQuestions, repeat);
    if (!have_r)
        std::printf(
            "  R comparison skipped: Rscript is not on the PATH (the bench installs "
            "nothing)\n");
    for (long size : sizes) {
        const analysis::SimulationSpec spec = design_of(size);
        const analysis::LongTable table = analysis::simulate_study(spec);
        const fs::path csv = dir / ("ratings_" + std::to_string(size) + ".csv");
        {
            std::ofstream out(csv, std::ios::binary);
            analysis::write_long_csv(out, table);
        }
        for (const char* model : {"lmm", "clmm"}) {
            const std::string label = std::string(model) + ", " +
                                      std::to_string(table.rows.size()) + " ratings";
            std::printf("  %s (%d participants)\n    %-10s %9s %9s %9s\n", label.c_str(),
                        spec.participants, "process", "wall s", "CPU s", "peak MiB");
            const fs::path report = dir / (std::string("lucent_") + model);
            const fs::path r_table = dir / (std::string("r_") + model + ".csv");
            std::vector<ProcessCost> lucent_runs, r_runs;
            for (int run = 0; run < repeat; ++run) {
                lucent_runs.push_back(
                    run_measured({self.string(), "analyze", csv.string(), "--out",
                                  report.string(), "--format", "csv", "--model", model}));
                if (have_r)
                    r_runs.push_back(
                        run_measured({"Rscript", (dir / "models.R").string(),
                                      csv.string(), r_table.string(), model}));
            }
            const ProcessCost lucent = median_cost(lucent_runs);
            if (!lucent.ok) {
                std::fprintf(stderr, "lucent bench stats: lucent analyze failed on %s\n",
                             csv.c_str());
                return kExitFailure;
            }
            print_cost("lucent", lucent);
            results.add("mixed " + label, "lucent wall", lucent.wall_s, "s");
            results.add("mixed " + label, "lucent cpu", lucent.cpu_s, "s");
            results.add("mixed " + label, "lucent peak memory", lucent.peak_mib, "MiB");
            if (!have_r) continue;
            const ProcessCost r = median_cost(r_runs);
            if (!r.ok) {
                std::printf(
                    "    R failed (are r-cran-lme4, r-cran-lmertest and "
                    "r-cran-ordinal installed?)\n");
                continue;
            }
            print_cost("R", r);
            const auto [effects, statistics] =
                largest_differences(lucent_estimates(report), r_estimates(r_table));
            std::printf(
                "    R / lucent: %.1fx wall, %.1fx CPU, %.1fx memory; largest "
                "relative difference: effects %.2g, test statistic %.2g\n",
                r.wall_s / lucent.wall_s, r.cpu_s / lucent.cpu_s,
                r.peak_mib / lucent.peak_mib, effects, statistics);
            results.add("mixed " + label, "R wall", r.wall_s, "s");
            results.add("mixed " + label, "R cpu", r.cpu_s, "s");
            results.add("mixed " + label, "R peak memory", r.peak_mib, "MiB");
            results.add("mixed " + label, "R / lucent (wall)", r.wall_s / lucent.wall_s,
                        "ratio");
            results.add("mixed " + label, "R / lucent (cpu)", r.cpu_s / lucent.cpu_s,
                        "ratio");
            results.add("mixed " + label, "largest effect difference", effects,
                        "relative");
            results.add("mixed " + label, "largest statistic difference", statistics,
                        "relative");
        }
    }
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    return kExitOk;
}

}  // namespace lucent::app
