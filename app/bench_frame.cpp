// lucent bench frame: median GPU frame time per mesh size. For the empirical technique
// (the default), the full shader against direct light only (ambient + diffuse +
// specular: backlight = 0, so no peeling or smoothing), as the thesis's Table 4.2 with
// the ratio per row. For any other technique, `--sweep KNOB=V1,V2,...` gives one row per
// mesh and value with the total, the costliest pass and the cost per unit of the value
// (the dipole's time per sample, as in Chang et al.'s Table 2). The AO bake is
// precomputed (cached) and not part of the frame, as in the thesis.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "output_file.h"
#include "gl/context.h"
#include "render.h"
#include "techniques/registry.h"

namespace lucent::app {
namespace {

struct FrameBenchOptions {
    std::string technique = "empirical";
    std::string sweep;  // KNOB=V1,V2,...: one row per mesh and value
    std::vector<std::string> settings;  // key=value for every row
    std::string mesh = "torus_knot";
    std::vector<std::string> faces = {"4k", "30k", "60k", "120k", "240k"};
    std::string size = "512x512";
    int frames = 60;
    int warmup = 3;
    std::string csv;  // the table, machine-readable (empty: none)
};

// Writes the printed table's rows (first row: the column names) as CSV.
bool write_table_csv(const std::string& path,
                     const std::vector<std::vector<std::string>>& table) {
    try {
        output::write_file_atomically(path, true, [&](std::ostream& out) {
            for (const auto& row : table) {
                for (std::size_t c = 0; c < row.size(); ++c)
                    out << (c ? "," : "")
                        << (row[c].find_first_of(",\"") == std::string::npos
                                ? row[c]
                                : '"' + row[c] + '"');
                out << '\n';
            }
        });
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", value);
    return text;
}

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
    // The GPU pass with the largest median: (name, ms).
    std::pair<std::string, double> costliest_pass() const {
        std::pair<std::string, double> costliest{"", 0.0};
        for (std::size_t p = 0; p < plan.passes.size(); ++p)
            if (!pass_ms[p].empty() && median(pass_ms[p]) >= costliest.second)
                costliest = {plan.passes[p].name, median(pass_ms[p])};
        return costliest;
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

int finish_csv(const FrameBenchOptions& options,
               const std::vector<std::vector<std::string>>& csv) {
    if (options.csv.empty()) return kExitOk;
    if (!write_table_csv(options.csv, csv)) {
        std::cerr << "lucent bench frame: --csv " << options.csv << ": cannot write\n";
        return kExitFailure;
    }
    std::cout << "table: " << options.csv << "\n";
    return kExitOk;
}

// --sweep KNOB=V1,V2,... (or the technique's first quality knob): rows of mesh x value.
int run_sweep_bench(const FrameBenchOptions& options, RenderRequest request,
                    gl::Context& context) {
    const Technique& technique = find_technique(options.technique);
    std::string knob_name;
    std::vector<std::string> values;
    if (!options.sweep.empty()) {
        KnobAssignment assignment;
        try {
            assignment = parse_assignment(options.sweep);
        } catch (const std::exception& e) {
            std::cerr << "lucent bench frame: --sweep: " << e.what() << "\n";
            return kExitUsage;
        }
        knob_name = assignment.key;
        const std::string& rest = assignment.text;
        for (std::size_t start = 0; start <= rest.size();) {
            const std::size_t comma = std::min(rest.find(',', start), rest.size());
            if (comma > start) values.push_back(rest.substr(start, comma - start));
            start = comma + 1;
        }
    } else {
        const auto sweeps = technique.quality_sweeps();
        if (sweeps.empty()) {
            std::cerr << "lucent bench frame: --technique " << options.technique
                      << " declares no quality knob: give --sweep KNOB=V1,V2,...\n";
            return kExitUsage;
        }
        knob_name = sweeps.front().knob;
        for (const auto& value : sweeps.front().values)
            values.push_back(format_knob_value(value));
    }
    const auto knobs = knobs_for(technique);
    const auto knob = std::find_if(knobs.begin(), knobs.end(),
                                   [&](const Knob& k) { return k.name == knob_name; });
    if (knob == knobs.end() || values.empty()) {
        std::cerr << "lucent bench frame: --sweep: '" << options.sweep
                  << "' is not KNOB=V1,V2,... with a knob of " << options.technique
                  << "\n";
        return kExitUsage;
    }
    const bool per_unit = knob->kind == KnobKind::integer || knob->kind == KnobKind::scalar;
    std::vector<KnobAssignment> fixed;
    try {
        for (const auto& setting : options.settings) fixed.push_back(parse_assignment(setting));
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: --set: " << e.what() << "\n";
        return kExitUsage;
    }
    std::ostringstream table, breakdowns;
    std::vector<std::vector<std::string>> csv = {
        {"mesh", "faces", knob_name, "total_ms", "fps", "costliest_pass", "pass_ms",
         per_unit ? "ms_per_unit" : "-"}};
    char line[240];
    std::snprintf(line, sizeof line, "%10s %10s | %12s %8s | %-16s %10s | %12s\n",
                  "faces", knob_name.c_str(), "total (ms)", "fps", "costliest pass", "ms",
                  per_unit ? "ms per unit" : "");
    table << line << std::string(94, '-') << "\n";
    bool gpu_timer = false;
    for (const auto& faces : options.faces) {
        request.mesh = options.mesh + ":" + faces;
        std::shared_ptr<const Mesh> mesh;
        for (const auto& value : values) {
            request.settings = fixed;
            request.settings.push_back({knob_name, value});
            Scene scene;
            try {
                scene = build_scene(request);
            } catch (const std::exception& e) {
                std::cerr << "lucent bench frame: " << e.what() << "\n";
                return kExitUsage;
            }
            if (mesh) scene.mesh = mesh;  // same mesh object: uploaded once
            mesh = scene.mesh;
            std::cerr << "measuring " << request.mesh << " (" << scene.mesh->face_count()
                      << " faces), " << knob_name << "=" << value << "...\n";
            Sampler sampler;
            sampler.plan = make_frame_plan(scene, technique);
            try {
                for (int i = 0; i < options.warmup + options.frames; ++i)
                    sampler.run(scene, i >= options.warmup);
            } catch (const std::exception& e) {
                std::cerr << "lucent bench frame: " << e.what() << "\n";
                return kExitFailure;
            }
            gpu_timer = sampler.executor.last_timings().gpu_timer;
            const double total_ms = median(sampler.frame_ms);
            const auto [pass, pass_ms] = sampler.costliest_pass();
            const double unit = per_unit ? std::stod(value) : 0.0;
            const double ms_per_unit = unit > 0.0 ? pass_ms / unit : 0.0;
            std::snprintf(line, sizeof line,
                          "%10zu %10s | %12.3f %8.2f | %-16s %10.3f | %12s\n",
                          scene.mesh->face_count(), value.c_str(), total_ms,
                          1000.0 / total_ms, pass.c_str(), pass_ms,
                          per_unit ? number(ms_per_unit).c_str() : "");
            table << line;
            breakdowns << "  " << scene.mesh->face_count() << " faces, " << knob_name << "="
                       << value << ": " << sampler.breakdown() << "\n";
            csv.push_back({request.mesh, std::to_string(scene.mesh->face_count()), value,
                           number(total_ms), number(1000.0 / total_ms), pass,
                           number(pass_ms), per_unit ? number(ms_per_unit) : ""});
        }
    }
    const gl::GlInfo info = context.info();
    std::cout << "lucent bench frame: " << options.technique << " on " << options.mesh
              << " at " << request.width << "x" << request.height << ", median of "
              << options.frames << " frames after " << options.warmup << " warm-up\n"
              << "GL: " << info.renderer << " (" << info.version << ")\n"
              << "timing: "
              << (gpu_timer ? "GL timer queries (GL_TIME_ELAPSED), summed over passes"
                            : "wall time around glFinish per pass (no timer queries)")
              << "; AO bake precomputed, not in the frame\n"
              << "every pass runs every frame (as when the light or material changes)\n\n"
              << table.str();
    if (per_unit)
        std::cout << "ms per unit = the costliest pass's median / " << knob_name << "\n";
    std::cout << "\nmedian per pass (ms):\n" << breakdowns.str();
    return finish_csv(options, csv);
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
    request.technique = options.technique;
    try {
        find_technique(options.technique);
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: --technique: " << e.what() << "\n";
        return kExitUsage;
    }
    if (options.technique != "empirical" || !options.sweep.empty())
        return run_sweep_bench(options, request, *context);
    const gl::GlInfo info = context->info();
    std::ostringstream table, breakdowns;
    bool gpu_timer = false;
    char line[200];
    std::snprintf(line, sizeof line, "%10s %10s | %12s %8s | %12s %8s | %6s\n", "faces",
                  "vertices", "full (ms)", "fps", "direct (ms)", "fps", "ratio");
    table << line << std::string(80, '-') << "\n";
    std::vector<std::vector<std::string>> csv = {
        {"mesh", "faces", "vertices", "full_ms", "direct_ms", "ratio"}};
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
        csv.push_back({request.mesh, std::to_string(full.mesh->face_count()),
                       std::to_string(full.mesh->vertex_count()), number(full_ms),
                       number(direct_ms), number(full_ms / direct_ms)});
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
    return finish_csv(options, csv);
}

}  // namespace

void register_bench_frame(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<FrameBenchOptions>();
    auto* cmd = bench.add_subcommand(
        "frame", "Median GPU frame time per mesh: full empirical shader vs direct light, or a technique's knob swept");
    cmd->add_option("--technique", options->technique,
                    "empirical: full vs direct light; another: rows of mesh x --sweep");
    cmd->add_option("--sweep", options->sweep,
                    "KNOB=V1,V2,...: one row per mesh and value (default for a technique "
                    "other than empirical: its first quality knob)");
    cmd->add_option("--set", options->settings,
                    "other parameters for every row of a --sweep, key=value (repeatable)");
    cmd->add_option("--mesh", options->mesh,
                    "built-in mesh family (face budgets from --faces)");
    cmd->add_option("--faces", options->faces, "face budgets, e.g. 4k 30k 60k 120k 240k")
        ->delimiter(',');
    cmd->add_option("--size", options->size, "frame size WxH");
    cmd->add_option("--frames", options->frames, "timed frames per row (median)");
    cmd->add_option("--warmup", options->warmup, "untimed frames first");
    cmd->add_option("--csv", options->csv, "also write the table as CSV (columns as printed)");
    cmd->callback([options, cmd, &exit_code] {
        // A technique other than the empirical one defaults to a size llvmpipe can do in
        // minutes (the dipole at N = 2500 costs seconds per 512x512 frame).
        FrameBenchOptions effective = *options;
        if (effective.technique != "empirical") {
            if (cmd->count("--size") == 0) effective.size = "128x128";
            if (cmd->count("--frames") == 0) effective.frames = 5;
            if (cmd->count("--warmup") == 0) effective.warmup = 1;
            if (cmd->count("--mesh") == 0) effective.mesh = "sphere";
            if (cmd->count("--faces") == 0) effective.faces = {"2k", "10k", "30k"};
        }
        exit_code = run_frame_bench(effective);
    });
}

}  // namespace lucent::app
