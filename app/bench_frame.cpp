// lucent bench frame: median GPU frame time of the full empirical shader and of direct
// light only (ambient + diffuse + specular: backlight = 0, so no peeling or smoothing),
// per mesh size, as the thesis's Table 4.2 with the ratio per row. The AO bake is
// precomputed (cached) and not part of the frame, as in the thesis.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "gl/context.h"
#include "render.h"
#include "techniques/registry.h"

namespace lucent::app {
namespace {

struct FrameBenchOptions {
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

// Median over `frames` frames of the summed GPU pass times (the CPU AO pass excluded).
double median_frame_ms(gl::FrameExecutor& executor, const Scene& scene, int frames, int warmup,
                       bool& gpu_timer) {
    const FramePlan plan = make_frame_plan(scene, find_technique(scene.technique));
    std::vector<double> times;
    for (int i = 0; i < warmup + frames; ++i) {
        executor.execute(scene, plan, /*time_passes=*/true);
        const auto& timings = executor.last_timings();
        gpu_timer = timings.gpu_timer;
        double ms = 0.0;
        for (std::size_t p = 0; p < timings.passes.size(); ++p)
            if (plan.passes[p].kind != PassKind::bake_ambient_occlusion) ms += timings.passes[p].milliseconds;
        if (i >= warmup) times.push_back(ms);
    }
    return median(times);
}

int run_frame_bench(const FrameBenchOptions& options) {
    RenderRequest request;
    if (std::sscanf(options.size.c_str(), "%dx%d", &request.width, &request.height) != 2 ||
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
    gl::FrameExecutor executor;
    std::ostringstream table;
    bool gpu_timer = false;
    char line[200];
    std::snprintf(line, sizeof line, "%10s %10s | %12s %8s | %12s %8s | %6s\n", "faces", "vertices",
                  "full (ms)", "fps", "direct (ms)", "fps", "ratio");
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
        std::cerr << "measuring " << request.mesh << " (" << full.mesh->face_count() << " faces)...\n";
        const double full_ms = median_frame_ms(executor, full, options.frames, options.warmup, gpu_timer);
        const double direct_ms = median_frame_ms(executor, direct, options.frames, options.warmup, gpu_timer);
        std::snprintf(line, sizeof line, "%10zu %10zu | %12.3f %8.1f | %12.3f %8.1f | %6.2f\n",
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
              << table.str() << "ratio = full / direct frame time\n";
    return kExitOk;
}

}  // namespace

void register_bench_frame(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<FrameBenchOptions>();
    auto* cmd = bench.add_subcommand("frame", "Median GPU frame time: full empirical shader vs direct light only");
    cmd->add_option("--mesh", options->mesh, "built-in mesh family (face budgets from --faces)");
    cmd->add_option("--faces", options->faces, "face budgets, e.g. 4k 30k 60k 120k 240k")->delimiter(',');
    cmd->add_option("--size", options->size, "frame size WxH");
    cmd->add_option("--frames", options->frames, "timed frames per row (median)");
    cmd->add_option("--warmup", options->warmup, "untimed frames first");
    cmd->callback([options, &exit_code] { exit_code = run_frame_bench(*options); });
}

}  // namespace lucent::app
