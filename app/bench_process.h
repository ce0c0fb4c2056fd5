#pragma once
// One program run as a whole process, measured: wall time, CPU time (user + system) and
// peak resident memory, for the benches that compare `lucent` with R on the same file.
#include <string>
#include <vector>

namespace lucent::app {

struct ProcessCost {
    bool ok = false;  // ran and exited 0
    double wall_s = 0.0, cpu_s = 0.0;
    double peak_mib = 0.0;  // the process's largest resident set
};

// Runs argv[0] (found on the PATH) with its output discarded, and waits for it.
ProcessCost run_measured(const std::vector<std::string>& argv);

// Per field, the median over runs (one run: itself); ok only when every run was.
ProcessCost median_cost(const std::vector<ProcessCost>& runs);

// True when `program` is on the PATH (e.g. Rscript; the benches install nothing).
bool on_path(const std::string& program);

}  // namespace lucent::app
