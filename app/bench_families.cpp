// The list of `lucent bench` families; one line per family.
#include "app/commands.h"

namespace lucent::app {

void register_bench_families(CLI::App& bench, int& exit_code) {
    register_bench_frame(bench, exit_code);
    register_bench_accuracy(bench, exit_code);
    register_bench_ao(bench, exit_code);
    register_bench_fidelity(bench, exit_code);
    register_bench_truth(bench, exit_code);
    register_bench_stats(bench, exit_code);
    register_bench_render(bench, exit_code);
    register_bench_store(bench, exit_code);
}

}  // namespace lucent::app
