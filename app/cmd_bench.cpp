// lucent bench: measured speed and accuracy tables. Each family registers its own
// sub-subcommand (bench_<family>.cpp); this file only creates the parent.
#include "app/commands.h"

namespace lucent::app {

void register_bench_adjust(CLI::App& bench, int& exit_code);  // bench_adjust.cpp

void register_bench(CLI::App& app, int& exit_code) {
    auto* bench = app.add_subcommand(
        "bench",
        "Measure speed and accuracy; each table is measured in one run and reported "
        "with ratios");
    bench->require_subcommand(1);
    register_bench_families(*bench, exit_code);
    register_bench_adjust(*bench, exit_code);
}

}  // namespace lucent::app
