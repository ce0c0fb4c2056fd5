// lucent bench frame: median GPU frame time of the full empirical shader and of direct
// light only (ambient + diffuse + specular: backlight = 0, so no peeling or smoothing),
// per mesh size, as the thesis's Table 4.2 with the ratio per row. The AO bake is
// precomputed (cached) and not part of the frame, as in the thesis. With --technique
// thick_texture: the thick texture (fast path, and the thesis's 8-texel path) against the
// same sheet with a plain alpha texture (h = 0), on `wave` with 100 to 12,800 triangles,
// as David-Babin's Table 4.1.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "gl/context.h"
#include "render.h"
#include "techniques/registry.h"

namespace lucent::app {
namespace {

struct FrameBenchOptions {
    std::string technique = "empirical";
    std::string mesh;                // default: torus_knot (empirical), wave (thick_texture)
    std::vector<std::string> faces;  // default: the thesis's table of the technique
    std::vector<std::string> settings;
    std::string size = "512x512";
    int frames = 60;
    int warmup = 3;
    std::string csv;
};

// What one table compares: the first variant against the last (the ratio column).
struct FrameVariant {
    std::string label;
    std::vector<KnobAssignment> settings;
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

int run_frame_bench(FrameBenchOptions options) {
    const bool thick = options.technique == "thick_texture";
    if (options.technique != "empirical" && !thick) {
        std::cerr << "lucent bench frame: --technique: '" << options.technique
                  << "' (accepted: empirical, thick_texture)\n";
        return kExitUsage;
    }
    if (options.mesh.empty()) options.mesh = thick ? "wave" : "torus_knot";
    if (options.faces.empty())
        options.faces = thick ? std::vector<std::string>{"100", "400", "800", "3200", "9600",
                                                         "12800"}
                              : std::vector<std::string>{"4k", "30k", "60k", "120k", "240k"};
    const std::vector<FrameVariant> variants =
        thick ? std::vector<FrameVariant>{{"thick (ms)", {}},
                                          {"thesis (ms)", {{"fetch_path", "thesis"}}},
                                          {"alpha (ms)", {{"thickness", "0"}}}}
              : std::vector<FrameVariant>{{"full (ms)", {}}, {"direct (ms)", {{"backlight", "0"}}}};
    RenderRequest request;
    request.technique = options.technique;
    if (std::sscanf(options.size.c_str(), "%dx%d", &request.width, &request.height) !=
            2 ||
        options.frames < 1) {
        std::cerr << "lucent bench frame: --size: '" << options.size << "' is not WxH\n";
        return kExitUsage;
    }
    std::vector<KnobAssignment> common;
    try {
        for (const auto& s : options.settings) common.push_back(parse_assignment(s));
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: " << e.what() << "\n";
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
    std::ostringstream table, breakdowns, csv;
    csv << "faces,vertices,variant,median_ms\n";
    bool gpu_timer = false;
    char line[256];
    std::snprintf(line, sizeof line, "%10s %10s |", "faces", "vertices");
    table << line;
    for (const auto& v : variants) {
        std::snprintf(line, sizeof line, " %12s %8s |", v.label.c_str(), "fps");
        table << line;
    }
    table << "  ratio\n" << std::string(24 + 24 * variants.size() + 8, '-') << "\n";
    for (const auto& faces : options.faces) {
        request.mesh = options.mesh + ":" + faces;
        std::vector<Scene> scenes;
        try {
            for (const auto& v : variants) {
                request.settings = common;
                request.settings.insert(request.settings.end(), v.settings.begin(),
                                        v.settings.end());
                scenes.push_back(build_scene(request));
                scenes.back().mesh = scenes.front().mesh;  // same mesh object: uploaded once
            }
        } catch (const std::exception& e) {
            std::cerr << "lucent bench frame: " << e.what() << "\n";
            return kExitUsage;
        }
        std::cerr << "measuring " << request.mesh << " (" << scenes[0].mesh->face_count()
                  << " faces)...\n";
        // Frames alternate between the variants (one executor each, so none
        // reallocates), so all see the same load on a shared machine.
        std::vector<Sampler> samplers(variants.size());
        for (std::size_t v = 0; v < variants.size(); ++v)
            samplers[v].plan = make_frame_plan(scenes[v], find_technique(scenes[v].technique));
        for (int i = 0; i < options.warmup + options.frames; ++i)
            for (std::size_t v = 0; v < variants.size(); ++v)
                samplers[v].run(scenes[v], i >= options.warmup);
        gpu_timer = samplers[0].executor.last_timings().gpu_timer;
        std::snprintf(line, sizeof line, "%10zu %10zu |", scenes[0].mesh->face_count(),
                      scenes[0].mesh->vertex_count());
        table << line;
        breakdowns << "  " << scenes[0].mesh->face_count() << " faces:";
        std::vector<double> ms;
        for (std::size_t v = 0; v < variants.size(); ++v) {
            ms.push_back(median(samplers[v].frame_ms));
            std::snprintf(line, sizeof line, " %12.3f %8.1f |", ms.back(), 1000.0 / ms.back());
            table << line;
            breakdowns << (v ? " | " : " ") << variants[v].label.substr(0, variants[v].label.find(' '))
                       << ": " << samplers[v].breakdown();
            csv << scenes[0].mesh->face_count() << "," << scenes[0].mesh->vertex_count() << ","
                << variants[v].label.substr(0, variants[v].label.find(' ')) << "," << ms.back()
                << "\n";
        }
        breakdowns << "\n";
        std::snprintf(line, sizeof line, " %6.2f\n", ms.front() / ms.back());
        table << line;
    }
    std::cout << "lucent bench frame: " << options.technique << " on " << options.mesh
              << " at " << request.width << "x" << request.height << ", median of "
              << options.frames << " frames after " << options.warmup << " warm-up\n"
              << "GL: " << info.renderer << " (" << info.version << ")\n"
              << "timing: "
              << (gpu_timer ? "GL timer queries (GL_TIME_ELAPSED), summed over passes"
                            : "wall time around glFinish per pass (no timer queries)")
              << (thick ? "; texture pyramids uploaded once, not in the frame\n"
                        : "; AO bake precomputed, not in the frame\n")
              << (thick ? "thick = Alg. 3.1 on hardware-filtered averages (3 fetches); thesis "
                          "= 8 texels x Alg. 3.1 (24 fetches); alpha = the same sheet with a "
                          "plain alpha texture (h = 0)\n\n"
                        : "full = empirical shader (AO, peel, 5x5 smoothing, Eq. 3.6); direct "
                          "= ambient + diffuse + specular (backlight 0)\n\n")
              << table.str() << "ratio = " << variants.front().label.substr(0, variants.front().label.find(' '))
              << " / " << variants.back().label.substr(0, variants.back().label.find(' '))
              << " frame time\n\n"
              << "median per pass (ms):\n"
              << breakdowns.str();
    if (!options.csv.empty()) {
        std::ofstream out(options.csv, std::ios::binary);
        out << csv.str();
        if (!out) {
            std::cerr << "lucent bench frame: --csv " << options.csv << ": cannot write\n";
            return kExitFailure;
        }
    }
    return kExitOk;
}

}  // namespace

void register_bench_frame(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<FrameBenchOptions>();
    auto* cmd = bench.add_subcommand(
        "frame", "Median GPU frame time: full empirical shader vs direct light only");
    cmd->add_option("--technique", options->technique,
                    "empirical (thesis Table 4.2) or thick_texture (David-Babin Table 4.1)");
    cmd->add_option("--mesh", options->mesh,
                    "built-in mesh family (face budgets from --faces; default torus_knot, "
                    "wave for thick_texture)");
    cmd->add_option("--set", options->settings, "parameters for every variant, key=value");
    cmd->add_option("--csv", options->csv, "also write faces,vertices,variant,median_ms");
    cmd->add_option("--faces", options->faces,
                    "face budgets, e.g. 4k,30k,60k,120k,240k (thick_texture: 100..12800)")
        ->delimiter(',');
    cmd->add_option("--size", options->size, "frame size WxH");
    cmd->add_option("--frames", options->frames, "timed frames per row (median)");
    cmd->add_option("--warmup", options->warmup, "untimed frames first");
    cmd->callback([options, &exit_code] { exit_code = run_frame_bench(*options); });
}

}  // namespace lucent::app
