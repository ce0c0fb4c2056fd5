// lucent bench frame: median GPU frame time of the full empirical shader and of direct
// light only (ambient + diffuse + specular: backlight = 0, so no peeling or smoothing),
// per mesh size, as the thesis's Table 4.2 with the ratio per row. The AO bake is
// precomputed (cached) and not part of the frame, as in the thesis.
#include <algorithm>
#include <fstream>
#include <memory>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "gl/context.h"
#include "render.h"
#include "techniques/htsm/htsm.h"
#include "techniques/registry.h"

namespace lucent::app {
namespace {

struct FrameBenchOptions {
    std::string technique = "empirical";  // empirical (Table 4.2) or htsm (Fig. 5.9)
    std::string csv;                      // htsm: the table, machine-readable
    std::string mesh = "torus_knot";
    std::vector<std::string> faces = {"4k", "30k", "60k", "120k", "240k"};
    std::string size = "512x512";
    int frames = 60;
    int warmup = 3;
};

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// One frame's GPU time: the sum of its GPU passes (the CPU AO pass excluded).
struct Sampler {
    gl::FrameExecutor executor;
    FramePlan plan;
    std::vector<double> frame_ms;
    std::vector<std::vector<double>> pass_ms;

    void run(const Scene& scene, bool record) {
        executor.execute(scene, plan, /*time_passes=*/true);
        const auto& timings = executor.last_timings();
        pass_ms.resize(plan.passes.size());
        double ms = 0.0;
        for (std::size_t p = 0; p < timings.passes.size(); ++p) {
            if (plan.passes[p].kind == PassKind::bake_ambient_occlusion) continue;
            ms += timings.passes[p].milliseconds;
            if (record) pass_ms[p].push_back(timings.passes[p].milliseconds);
        }
        if (record) frame_ms.push_back(ms);
    }
    // "name ms, name ms" with each GPU pass's median.
    std::string breakdown() const {
        std::string text;
        char item[64];
        for (std::size_t p = 0; p < plan.passes.size(); ++p) {
            if (pass_ms[p].empty()) continue;
            std::snprintf(item, sizeof item, "%s%s %.2f", text.empty() ? "" : ", ",
                          plan.passes[p].name.c_str(), median(pass_ms[p]));
            text += item;
        }
        return text;
    }
};

// Shopf's Fig. 5.9: frame time for n = 1, 5, 9, 13 rays at the default S, one mesh
// (the first --faces budget), frames of the four variants interleaved; the ratio to
// n = 1 (the thesis: 8.8-11.5x for n = 13 on three GPUs) and the fetches per pixel.
int run_htsm_frame_bench(const FrameBenchOptions& options, RenderRequest request,
                         const gl::GlInfo& info) {
    request.technique = "htsm";
    request.mesh = options.mesh + ":" + options.faces.front();
    const std::vector<int> rays = {1, 5, 9, 13};
    std::vector<Scene> scenes;
    std::vector<std::unique_ptr<Sampler>> samplers;
    try {
        for (int n : rays) {
            RenderRequest r = request;
            r.settings.push_back({"rays", std::to_string(n)});
            scenes.push_back(build_scene(r));
            if (scenes.size() > 1) scenes.back().mesh = scenes.front().mesh;
            samplers.push_back(std::make_unique<Sampler>());
            samplers.back()->plan = make_frame_plan(scenes.back(), find_technique("htsm"));
        }
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: " << e.what() << "\n";
        return kExitUsage;
    }
    std::cerr << "measuring htsm on " << request.mesh << "...\n";
    for (int i = 0; i < options.warmup + options.frames; ++i)
        for (std::size_t v = 0; v < rays.size(); ++v)
            samplers[v]->run(scenes[v], i >= options.warmup);
    const double base = median(samplers[0]->frame_ms);
    std::ostringstream table, csv, breakdowns;
    char line[200];
    std::snprintf(line, sizeof line, "%6s | %12s %8s | %10s | %12s\n", "rays n", "frame (ms)",
                  "fps", "ratio", "fetches/px");
    table << line << std::string(60, '-') << "\n";
    csv << "rays,frame_ms,fps,ratio_to_n1,fetches_per_pixel,steps,light_map_size\n";
    const htsm::Params p = htsm::params(scenes[0]);
    for (std::size_t v = 0; v < rays.size(); ++v) {
        const double ms = median(samplers[v]->frame_ms);
        const int fetches = htsm::fetches_per_pixel(scenes[v]);
        std::snprintf(line, sizeof line, "%6d | %12.3f %8.1f | %10.2f | %12d\n", rays[v], ms,
                      1000.0 / ms, ms / base, fetches);
        table << line;
        csv << rays[v] << "," << ms << "," << 1000.0 / ms << "," << ms / base << ","
            << fetches << "," << p.steps << "," << p.light_map_size << "\n";
        breakdowns << "  n = " << rays[v] << ": " << samplers[v]->breakdown() << "\n";
    }
    std::cout << "lucent bench frame --technique htsm: " << request.mesh << " at "
              << request.width << "x" << request.height << ", S = " << p.steps
              << ", W_L = " << p.light_map_size << ", median of " << options.frames
              << " frames after " << options.warmup << " warm-up (variants interleaved)\n"
              << "GL: " << info.renderer << " (" << info.version << ")\n\n"
              << table.str()
              << "ratio = frame time / frame time at n = 1 (Shopf Fig. 5.9: n = 13 costs "
                 "8.8-11.5x n = 1 on three GPUs)\n\nmedian per pass (ms):\n"
              << breakdowns.str();
    if (!options.csv.empty()) {
        std::ofstream out(options.csv);
        out << csv.str();
        if (!out) {
            std::cerr << "lucent bench frame: --csv: cannot write " << options.csv << "\n";
            return kExitFailure;
        }
        std::cout << "wrote " << options.csv << "\n";
    }
    return kExitOk;
}

int run_frame_bench(const FrameBenchOptions& options) {
    RenderRequest request;
    if (std::sscanf(options.size.c_str(), "%dx%d", &request.width, &request.height) !=
            2 ||
        options.frames < 1) {
        std::cerr << "lucent bench frame: --size: '" << options.size << "' is not WxH\n";
        return kExitUsage;
    }
    std::unique_ptr<gl::Context> context;
    try {
        context = gl::create_headless_context();
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: " << e.what() << "\n";
        return kExitFailure;
    }
    const gl::GlInfo info = context->info();
    if (options.technique == "htsm") return run_htsm_frame_bench(options, request, info);
    if (options.technique != "empirical") {
        std::cerr << "lucent bench frame: --technique: '" << options.technique
                  << "' (accepted: empirical, htsm)\n";
        return kExitUsage;
    }
    std::ostringstream table, breakdowns;
    bool gpu_timer = false;
    char line[200];
    std::snprintf(line, sizeof line, "%10s %10s | %12s %8s | %12s %8s | %6s\n", "faces",
                  "vertices", "full (ms)", "fps", "direct (ms)", "fps", "ratio");
    table << line << std::string(80, '-') << "\n";
    for (const auto& faces : options.faces) {
        request.mesh = options.mesh + ":" + faces;
        request.settings.clear();
        Scene full, direct;
        try {
            full = build_scene(request);
            request.settings = {{"backlight", "0"}};
            direct = build_scene(request);
            direct.mesh = full.mesh;  // same mesh object: uploaded once
        } catch (const std::exception& e) {
            std::cerr << "lucent bench frame: " << e.what() << "\n";
            return kExitUsage;
        }
        std::cerr << "measuring " << request.mesh << " (" << full.mesh->face_count()
                  << " faces)...\n";
        // Frames alternate between the two variants (one executor each, so neither
        // reallocates), so both see the same load on a shared machine.
        Sampler full_sampler, direct_sampler;
        full_sampler.plan = make_frame_plan(full, find_technique(full.technique));
        direct_sampler.plan = make_frame_plan(direct, find_technique(direct.technique));
        for (int i = 0; i < options.warmup + options.frames; ++i) {
            full_sampler.run(full, i >= options.warmup);
            direct_sampler.run(direct, i >= options.warmup);
        }
        gpu_timer = full_sampler.executor.last_timings().gpu_timer;
        const double full_ms = median(full_sampler.frame_ms);
        const double direct_ms = median(direct_sampler.frame_ms);
        breakdowns << "  " << full.mesh->face_count()
                   << " faces: full: " << full_sampler.breakdown()
                   << " | direct: " << direct_sampler.breakdown() << "\n";
        std::snprintf(
            line, sizeof line, "%10zu %10zu | %12.3f %8.1f | %12.3f %8.1f | %6.2f\n",
            full.mesh->face_count(), full.mesh->vertex_count(), full_ms, 1000.0 / full_ms,
            direct_ms, 1000.0 / direct_ms, full_ms / direct_ms);
        table << line;
    }
    std::cout << "lucent bench frame: " << options.mesh << " at " << request.width << "x"
              << request.height << ", median of " << options.frames << " frames after "
              << options.warmup << " warm-up\n"
              << "GL: " << info.renderer << " (" << info.version << ")\n"
              << "timing: "
              << (gpu_timer ? "GL timer queries (GL_TIME_ELAPSED), summed over passes"
                            : "wall time around glFinish per pass (no timer queries)")
              << "; AO bake precomputed, not in the frame\n"
              << "full = empirical shader (AO, peel, 5x5 smoothing, Eq. 3.6); direct = "
                 "ambient + diffuse + specular (backlight 0)\n\n"
              << table.str() << "ratio = full / direct frame time\n\n"
              << "median per pass (ms):\n"
              << breakdowns.str();
    return kExitOk;
}

}  // namespace

void register_bench_frame(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<FrameBenchOptions>();
    auto* cmd = bench.add_subcommand(
        "frame", "Median GPU frame time: full empirical shader vs direct light only");
    cmd->add_option("--technique", options->technique,
                    "empirical (full vs direct per mesh size) or htsm (n = 1, 5, 9, 13 "
                    "rays on the first --faces budget)");
    cmd->add_option("--csv", options->csv, "htsm: write the table as CSV");
    cmd->add_option("--mesh", options->mesh,
                    "built-in mesh family (face budgets from --faces)");
    cmd->add_option("--faces", options->faces, "face budgets, e.g. 4k 30k 60k 120k 240k")
        ->delimiter(',');
    cmd->add_option("--size", options->size, "frame size WxH");
    cmd->add_option("--frames", options->frames, "timed frames per row (median)");
    cmd->add_option("--warmup", options->warmup, "untimed frames first");
    cmd->callback([options, &exit_code] { exit_code = run_frame_bench(*options); });
}

}  // namespace lucent::app
