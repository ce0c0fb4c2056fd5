// The list of `lucent bench` families; one line per family.
#include "commands.h"

namespace lucent::app {

void register_bench_families(CLI::App& bench, int& exit_code) {
    (void)bench;
    (void)exit_code;
}

}  // namespace lucent::app
