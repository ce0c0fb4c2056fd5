// lucent bench adjust: the adjust trial's frame after one knob step (issue 31): the
// match re-rendered with the knob moved, read back, encoded and put in its texture, as
// `lucent run` does, with pass reuse (only the passes the knob touches re-run) against
// a full render (every pass), on the registry's default technique (the empirical shader)
// or the one named, per size; median and p95 and their ratios, measured in one run on
// this machine.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/bench_results.h"
#include "app/commands.h"
#include "renderer/gl/context.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "study/session/live_knob.h"

namespace lucent::app {
namespace {

struct AdjustBenchOptions {
    std::string mesh = "sphere:10k";
    std::string technique = default_technique_name();
    std::string knob = "thickness_exponent";
    std::vector<int> sizes = {256, 512};
    int frames = 30;
    int warmup = 3;
    std::string csv;
};

double quantile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    const double at = q * (v.size() - 1);
    const size_t i = static_cast<size_t>(at);
    return i + 1 < v.size() ? v[i] + (at - i) * (v[i + 1] - v[i]) : v.back();
}

// Frame times (ms) of `frames` knob steps, alternating up and down by a coarse step
// (a factor 10^0.05, as the built-in matching study's arrows), so every frame shows a
// new value. The renderers take turns frame by frame, so all see the same load on a
// shared machine.
struct Steps {
    std::vector<double> ms, ran;
    int total = 0;
    std::string last_run;  // the passes the last step ran
};
std::vector<Steps> knob_steps(const std::vector<study::LiveKnobRenderer*>& renderers,
                              double value, const AdjustBenchOptions& o) {
    using Clock = std::chrono::steady_clock;
    std::vector<Steps> steps(renderers.size());
    for (int i = 0; i < o.warmup + o.frames; ++i) {
        const double v = value * std::pow(10.0, (i % 2 ? 0.05 : -0.05));
        for (size_t k = 0; k < renderers.size(); ++k) {
            const auto start = Clock::now();
            renderers[k]->render(v);
            const double elapsed =
                std::chrono::duration<double, std::milli>(Clock::now() - start).count();
            if (i < o.warmup) continue;
            steps[k].ms.push_back(elapsed);
            int n = 0;
            steps[k].last_run.clear();
            for (const auto& p : renderers[k]->last_timings().passes) {
                n += p.cached ? 0 : 1;
                if (!p.cached)
                    steps[k].last_run += (steps[k].last_run.empty() ? "" : ", ") + p.pass;
            }
            steps[k].ran.push_back(n);
            steps[k].total = static_cast<int>(renderers[k]->last_timings().passes.size());
        }
    }
    return steps;
}

int run_adjust_bench(const AdjustBenchOptions& o) {
    if (o.frames < 2 || o.sizes.empty()) {
        std::cerr << "lucent bench adjust: --frames must be at least 2 and --sizes "
                     "given\n";
        return kExitUsage;
    }
    if (!is_technique_name(o.technique)) {
        std::cerr << "lucent bench adjust: --technique: '" << o.technique
                  << "' is unknown (valid: " << technique_names_listed() << ")\n";
        return kExitUsage;
    }
    const auto knobs = knobs_for(find_technique(o.technique));
    const Knob* knob = find_knob(knobs, o.knob);
    if (!knob || knob->kind != KnobKind::scalar) {
        std::cerr << "lucent bench adjust: --knob: '" << o.knob
                  << "' is not a number knob of " << o.technique << "\n";
        return kExitUsage;
    }
    std::unique_ptr<gl::Context> context;
    try {
        context = gl::create_headless_context();
    } catch (const std::exception& e) {
        std::cerr << "lucent bench adjust: " << e.what() << "\n";
        return kExitFailure;
    }
    const gl::GlInfo info = context->info();
    std::cout << "lucent bench adjust: an adjust trial's match after one knob step ("
              << o.knob << ", " << o.technique << ", " << o.mesh
              << "), rendered, read back and "
              << "uploaded as `lucent run` does\nGL: " << info.renderer << "\n"
              << o.frames << " frames per row after " << o.warmup << " warm-up\n\n";
    char line[256];
    std::snprintf(line, sizeof line, "%6s | %10s %10s %9s | %10s %10s %9s | %8s %8s",
                  "size", "reuse p50", "reuse p95", "passes", "full p50", "full p95",
                  "passes", "full/reuse", "p95");
    std::cout << line << "\n" << std::string(std::strlen(line), '-') << "\n";
    BenchResults results;
    for (const int size : o.sizes) {
        RenderRequest request;
        request.mesh = o.mesh;
        request.technique = o.technique;
        request.width = request.height = size;
        try {
            const Scene scene = build_scene(request);
            const double value = scene.values.scalar(o.knob);
            study::LiveKnobRenderer reuse("match", scene, o.knob, size, size, true);
            study::LiveKnobRenderer full("match", scene, o.knob, size, size, false);
            const std::vector<Steps> steps = knob_steps({&reuse, &full}, value, o);
            const std::vector<double>&r = steps[0].ms, &f = steps[1].ms;
            const double reuse_ran = quantile(steps[0].ran, 0.5);
            const double full_ran = quantile(steps[1].ran, 0.5);
            const int total = steps[0].total;
            const double r50 = quantile(r, 0.5), r95 = quantile(r, 0.95);
            const double f50 = quantile(f, 0.5), f95 = quantile(f, 0.95);
            std::snprintf(
                line, sizeof line,
                "%6d | %8.2f ms %8.2f ms %4.0f of %-2d | %8.2f ms %8.2f ms %4.0f "
                "of %-2d | %9.2fx %7.2fx",
                size, r50, r95, reuse_ran, total, f50, f95, full_ran, total, f50 / r50,
                f95 / r95);
            std::cout << line << "   (reuse ran: " << steps[0].last_run << ")\n";
            const std::string section = std::to_string(size) + "x" + std::to_string(size);
            results.add(section, "reuse_median", r50, "ms");
            results.add(section, "reuse_p95", r95, "ms");
            results.add(section, "reuse_passes_run", reuse_ran, "passes");
            results.add(section, "full_median", f50, "ms");
            results.add(section, "full_p95", f95, "ms");
            results.add(section, "full_passes_run", full_ran, "passes");
            results.add(section, "full_over_reuse_median", f50 / r50, "ratio");
            results.add(section, "full_over_reuse_p95", f95 / r95, "ratio");
        } catch (const std::exception& e) {
            std::cerr << "lucent bench adjust: " << e.what() << "\n";
            return kExitFailure;
        }
    }
    std::cout << "\nreuse: one executor with pass reuse (what `lucent run` uses); full: "
                 "every pass every frame\n";
    if (!o.csv.empty()) {
        if (!results.write_csv(o.csv)) {
            std::cerr << "lucent bench adjust: --csv " << o.csv << ": cannot write\n";
            return kExitFailure;
        }
        std::cout << "table: " << o.csv << "\n";
    }
    return kExitOk;
}

}  // namespace

void register_bench_adjust(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<AdjustBenchOptions>();
    auto* cmd = bench.add_subcommand(
        "adjust",
        "An adjust trial's frame after one knob step: pass reuse vs a full render");
    cmd->add_option("--mesh", options->mesh, "mesh (built-in name[:faces] or a file)")
        ->capture_default_str();
    cmd->add_option("--technique", options->technique,
                    "the technique rendered (" + technique_names_listed() + ")")
        ->capture_default_str();
    cmd->add_option("--knob", options->knob, "the technique's number knob turned")
        ->capture_default_str();
    cmd->add_option("--sizes", options->sizes, "square frame sizes in pixels")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--frames", options->frames, "timed knob steps per row")
        ->capture_default_str();
    cmd->add_option("--warmup", options->warmup, "untimed steps first")
        ->capture_default_str();
    cmd->add_option("--csv", options->csv, "also write section,name,value,unit rows");
    cmd->callback([options, &exit_code] { exit_code = run_adjust_bench(*options); });
}

}  // namespace lucent::app
