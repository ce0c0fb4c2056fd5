// lucent bench render: stimuli per second for the built-in `thesis` set (512x512 unless
// --size), and where the time goes: AO baking, GL rendering (plan, passes, read-back),
// image encoding, statistics + content hashes. Run twice in one process: with an empty
// AO cache (a fresh machine) and with the cache the first run filled.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "batch_render.h"
#include "commands.h"

namespace lucent::app {
namespace {

struct RenderBenchOptions {
    std::string size = "512x512";
    int jobs = 1;
};

void print_row(const char* label, std::size_t stimuli, const stimuli::BatchTimings& t,
               int jobs) {
    // Shares of the workers' time (wall time x jobs); "other" is mesh loading, hashing
    // decisions, manifest writing and idle workers.
    const double total = t.wall_seconds * jobs;
    const double other =
        total - t.ao_seconds - t.gl_seconds - t.encode_seconds - t.statistics_seconds;
    auto share = [&](double seconds) {
        return total > 0 ? 100.0 * seconds / total : 0.0;
    };
    std::printf("%-11s %9.2f %8.2f %7.1f %7.1f %9.1f %12.1f %8.1f\n", label,
                t.wall_seconds > 0 ? double(stimuli) / t.wall_seconds : 0.0,
                t.wall_seconds, share(t.ao_seconds), share(t.gl_seconds),
                share(t.encode_seconds), share(t.statistics_seconds), share(other));
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
    auto set = stimuli::load_preset("thesis", stimuli::default_catalog());
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
    try {
        std::printf(
            "lucent bench render: '%s' set, %zu stimuli at %dx%d, %d job(s), formats:",
            set.name.c_str(), set.stimuli.size(), width, height, options.jobs);
        for (const auto format : set.formats)
            std::printf(" %s", std::string(stimuli::extension(format)).c_str());
        std::printf("\nshares are of worker time (wall x jobs)\n\n");
        std::printf("%-11s %9s %8s %7s %7s %9s %12s %8s\n", "AO cache", "stimuli/s",
                    "wall s", "AO %", "GL %", "encode %", "stats+hash %", "other %");
        stimuli::BatchOptions batch;
        batch.out_dir = scratch / "out";
        batch.jobs = options.jobs;
        batch.force = true;
        batch.progress = false;
        const auto cold = stimuli::render_stimulus_set(set, batch);
        print_row("empty", cold.rendered, cold.timings, options.jobs);
        const auto warm = stimuli::render_stimulus_set(set, batch);
        print_row("filled", warm.rendered, warm.timings, options.jobs);
        std::printf(
            "\nfilled / empty cache throughput: %.2fx\n",
            cold.timings.wall_seconds / std::max(warm.timings.wall_seconds, 1e-9));
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
    cmd->add_option("--jobs", options->jobs, "parallel workers (default 1)");
    cmd->callback([options, &exit_code] { exit_code = run_render_bench(*options); });
}

}  // namespace lucent::app
