#include "app/bench_process.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>

namespace lucent::app {

ProcessCost run_measured(const std::vector<std::string>& argv) {
    ProcessCost cost;
    if (argv.empty()) return cost;
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid < 0) return cost;
    if (pid == 0) {
        const int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, STDOUT_FILENO);
            dup2(null, STDERR_FILENO);
        }
        execvp(args[0], args.data());
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    if (wait4(pid, &status, 0, &usage) != pid) return cost;
    cost.wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    auto seconds = [](const timeval& t) {
        return double(t.tv_sec) + 1e-6 * double(t.tv_usec);
    };
    cost.cpu_s = seconds(usage.ru_utime) + seconds(usage.ru_stime);
    cost.peak_mib = double(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
    cost.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    return cost;
}

ProcessCost median_cost(const std::vector<ProcessCost>& runs) {
    ProcessCost median;
    if (runs.empty()) return median;
    auto median_of = [&](double ProcessCost::*field) {
        std::vector<double> values;
        for (const auto& run : runs) values.push_back(run.*field);
        std::sort(values.begin(), values.end());
        const std::size_t n = values.size();
        return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
    };
    median.ok = std::all_of(runs.begin(), runs.end(), [](const auto& r) { return r.ok; });
    median.wall_s = median_of(&ProcessCost::wall_s);
    median.cpu_s = median_of(&ProcessCost::cpu_s);
    median.peak_mib = median_of(&ProcessCost::peak_mib);
    return median;
}

bool on_path(const std::string& program) {
    return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

}  // namespace lucent::app
