// lucent stats: the studentized range distribution at the command line, 17 significant
// digits, so analysts can use the numbers directly.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "analysis/stats/studentized_range.h"
#include "app/commands.h"
#include "common/number_text.h"

namespace lucent::app {
namespace {

// "inf" (or "infinity") or a number >= 1.
double parse_df(const std::string& text) {
    if (text == "inf" || text == "infinity" || text == "Inf")
        return analysis::kInfiniteDf;
    const auto value = common::parse_finite_number(text);
    if (!value)
        throw std::domain_error("--df: expected a number or 'inf', got '" + text + "'");
    return *value;
}

void print_full(double x) { std::printf("%s\n", common::full_precision_text(x).c_str()); }

int guarded(const char* name, const std::function<void()>& body) {
    try {
        body();
        return kExitOk;
    } catch (const std::domain_error& e) {
        std::cerr << "lucent stats " << name << ": " << e.what() << "\n";
        return kExitUsage;
    }
}

}  // namespace

void register_stats(CLI::App& app, int& exit_code) {
    auto* stats =
        app.add_subcommand("stats", "Distribution functions used by the analysis");
    stats->require_subcommand(1);

    struct Args {
        double q = 0, p = 0;
        int k = 0;
        std::string df;
        bool lower = false;
    };
    auto args = std::make_shared<Args>();
    auto* ptukey = stats->add_subcommand(
        "ptukey", "Studentized range: P(Q > q) (a p-value), or P(Q <= q) with --lower");
    ptukey->add_option("--q", args->q, "Studentized range statistic (>= 0)")->required();
    ptukey->add_option("--k", args->k, "Number of groups (2..200)")->required();
    ptukey->add_option("--df", args->df, "Error degrees of freedom (>= 1, or inf)")
        ->required();
    ptukey->add_flag("--lower", args->lower, "Print the CDF P(Q <= q) instead");
    ptukey->callback([args, &exit_code] {
        exit_code = guarded("ptukey", [&] {
            const double df = parse_df(args->df);
            print_full(args->lower
                           ? analysis::studentized_range_cdf(args->q, args->k, df)
                           : analysis::studentized_range_upper(args->q, args->k, df));
        });
    });

    auto* qtukey = stats->add_subcommand(
        "qtukey", "Studentized range: the q whose upper-tail probability P(Q > q) is p");
    qtukey->add_option("--p", args->p, "Upper-tail probability, 0 < p < 1")->required();
    qtukey->add_option("--k", args->k, "Number of groups (2..200)")->required();
    qtukey->add_option("--df", args->df, "Error degrees of freedom (>= 1, or inf)")
        ->required();
    qtukey->callback([args, &exit_code] {
        exit_code = guarded("qtukey", [&] {
            print_full(analysis::studentized_range_quantile_upper(args->p, args->k,
                                                                  parse_df(args->df)));
        });
    });
}

}  // namespace lucent::app
