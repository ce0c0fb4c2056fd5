// lucent bench render: stimuli per second for the built-in `thesis` set (512x512 unless
// --size), and where the time goes: AO baking, GL rendering (plan, passes, read-back),
// image encoding, statistics + content hashes (rendering and encoding overlap). Run twice
// in one process: with an empty AO cache (a fresh machine) and with the cache the first
// run filled.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>

#include "app/bench_results.h"
#include "app/commands.h"
#include "stimuli/batch_render.h"

namespace lucent::app {
namespace {

struct RenderBenchOptions {
    std::string size = "512x512";
    int jobs = 1;
    std::string csv;
};

// Seconds per stage, summed over workers. Render workers (AO + GL) and encode workers
// (encode + stats/hash) overlap, so "busy" (all stages over wall time) can exceed 1.
// `cpu`: process CPU seconds of the batch (all threads, llvmpipe's included), the
// measure least affected by other load on the machine.
void print_row(const char* label, std::size_t stimuli, const stimuli::BatchTimings& t,
               double cpu, BenchResults& results) {
    const double rate = t.wall_seconds > 0 ? double(stimuli) / t.wall_seconds : 0.0;
    const double cpu_rate = cpu > 0 ? double(stimuli) / cpu : 0.0;
    const double busy =
        t.ao_seconds + t.gl_seconds + t.encode_seconds + t.statistics_seconds;
    std::printf("%-14s %9.2f %8.2f %7.2f %10.2f %7.2f %7.2f %9.2f %8.2f %7.2f\n", label,
                rate, t.wall_seconds, cpu, cpu_rate, t.ao_seconds, t.gl_seconds,
                t.encode_seconds, t.statistics_seconds,
                t.wall_seconds > 0 ? busy / t.wall_seconds : 0.0);
    const std::string section = std::string("AO cache ") + label;
    results.add(section, "stimuli per second", rate, "1/s");
    results.add(section, "wall", t.wall_seconds, "s");
    results.add(section, "CPU", cpu, "s");
    results.add(section, "stimuli per CPU-second", cpu_rate, "1/CPUs");
    results.add(section, "AO", t.ao_seconds, "s");
    results.add(section, "GL", t.gl_seconds, "s");
    results.add(section, "encode", t.encode_seconds, "s");
    results.add(section, "stats+hash", t.statistics_seconds, "s");
    results.add(section, "stages over wall", busy / std::max(t.wall_seconds, 1e-9),
                "ratio");
}

int run_render_bench(const RenderBenchOptions& options) {
    int width = 0, height = 0;
    if (std::sscanf(options.size.c_str(), "%dx%d", &width, &height) != 2 || width < 1 ||
        height < 1 || width > 8192 || height > 8192 || options.jobs < 1 ||
        options.jobs > 64) {
        std::cerr << "lucent bench render: --size WxH with each in [1, 8192] and --jobs "
                     "in 1..64\n";
        return kExitUsage;
    }
    auto set = load_set_preset("thesis", default_set_catalog());
    set.width = width;
    set.height = height;

    // A private output directory and AO cache, removed afterwards; the user's cache is
    // left alone (and restored in the environment).
    const auto scratch = std::filesystem::temp_directory_path() /
                         ("lucent-bench-render-" + std::to_string(::getpid()));
    std::filesystem::remove_all(scratch);
    const char* previous_cache = std::getenv("LUCENT_CACHE_DIR");
    const std::string saved_cache = previous_cache ? previous_cache : "";
    ::setenv("LUCENT_CACHE_DIR", (scratch / "cache").c_str(), 1);

    int code = kExitOk;
    BenchResults results;
    try {
        std::printf(
            "lucent bench render: '%s' set, %zu stimuli at %dx%d, %d job(s), formats:",
            set.name.c_str(), set.stimuli.size(), width, height, options.jobs);
        for (const auto format : set.formats)
            std::printf(" %s", std::string(image_extension(format)).c_str());
        std::printf(
            "\nstage seconds are summed over workers: %d render (AO, GL) and %d encode "
            "(encode, stats+hash) workers run at once; busy = stages / wall;\nCPU s: "
            "process "
            "CPU time, llvmpipe's threads included (less affected by other load)\n\n",
            options.jobs, options.jobs);
        std::printf("%-14s %9s %8s %7s %10s %7s %7s %9s %8s %7s\n", "AO cache",
                    "stimuli/s", "wall s", "CPU s", "stimuli/", "AO s", "GL s",
                    "encode s", "stats s", "busy");
        std::printf("%-14s %9s %8s %7s %10s\n", "", "", "", "", "CPU s");
        stimuli::BatchOptions batch;
        batch.out_dir = scratch / "out";
        batch.jobs = options.jobs;
        batch.force = true;
        batch.progress = false;
        // One batch; returns its wall and CPU seconds.
        const auto run = [&](const char* label, const stimuli::BatchOptions& how) {
            const std::clock_t start = std::clock();
            const auto done = stimuli::render_stimulus_set(set, how);
            const double cpu = double(std::clock() - start) / CLOCKS_PER_SEC;
            print_row(label, done.rendered, done.timings, cpu, results);
            return std::pair{done.timings.wall_seconds, cpu};
        };
        const auto cold = run("empty", batch);
        // Filled cache, the way a set was written before (each render worker encodes its
        // own images, libpng's default PNG compression) and now, alternating, twice each.
        stimuli::BatchOptions before = batch;
        before.overlap_encode = false;
        before.png = PngEncoding::compact;
        double before_wall = 0, before_cpu = 0, now_wall = 0, now_cpu = 0;
        for (int round = 0; round < 2; ++round) {
            const auto [bw, bc] = run("filled, before", before);
            const auto [nw, nc] = run("filled", batch);
            before_wall += bw, before_cpu += bc, now_wall += nw, now_cpu += nc;
        }
        std::printf(
            "%-14s: serial encode, libpng default PNG compression (the previous "
            "way; same pixels)\n",
            "filled, before");
        const double speedup = cold.first / std::max(now_wall / 2, 1e-9);
        const double wall_gain = before_wall / std::max(now_wall, 1e-9);
        const double cpu_gain = before_cpu / std::max(now_cpu, 1e-9);
        std::printf("\nfilled / empty cache throughput: %.2fx\n", speedup);
        std::printf(
            "filled, now / before: %.2fx stimuli per second, %.2fx stimuli per "
            "CPU-second\n",
            wall_gain, cpu_gain);
        results.add("summary", "filled / empty cache throughput", speedup, "ratio");
        results.add("summary", "filled now / before, stimuli per second", wall_gain,
                    "ratio");
        results.add("summary", "filled now / before, stimuli per CPU-second", cpu_gain,
                    "ratio");
        if (!options.csv.empty() && !results.write_csv(options.csv))
            throw std::runtime_error("--csv: cannot write '" + options.csv + "'");
    } catch (const std::exception& e) {
        std::cerr << "lucent bench render: " << e.what() << "\n";
        code = kExitFailure;
    }
    if (previous_cache)
        ::setenv("LUCENT_CACHE_DIR", saved_cache.c_str(), 1);
    else
        ::unsetenv("LUCENT_CACHE_DIR");
    std::error_code ignored;
    std::filesystem::remove_all(scratch, ignored);
    return code;
}

}  // namespace

void register_bench_render(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<RenderBenchOptions>();
    auto* cmd = bench.add_subcommand(
        "render",
        "Stimuli per second for the thesis set and the share of AO baking, GL "
        "rendering and image encoding");
    cmd->add_option("--size", options->size,
                    "image size WxH (default 512x512, the set's own)");
    cmd->add_option("--jobs", options->jobs,
                    "render workers, and as many encode workers (default 1)");
    cmd->add_option(
        "--csv", options->csv,
        "Also write every number as CSV (section,name,value,unit) to this file");
    cmd->callback([options, &exit_code] { exit_code = run_render_bench(*options); });
}

}  // namespace lucent::app
