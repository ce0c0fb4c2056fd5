// lucent bench frame: median GPU frame time per mesh size. A technique that declares a
// comparison (Technique::frame_comparison: the empirical shader's full vs direct light,
// as the thesis's Table 4.2) gets its variants per mesh with the ratio to the baseline;
// otherwise, or with `--sweep KNOB=V1,V2,...`, one row per mesh and value with the
// total, the costliest pass and the cost per unit of the value (the dipole's time per
// sample, as Chang et al.'s Table 2). Bakes (ProductionCost::bake uploads: the AO) are
// precomputed (cached) and not part of the frame, as in the thesis.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.h"
#include "common/output_file.h"
#include "renderer/gl/context.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"

namespace lucent::app {
namespace {

struct FrameBenchOptions {
    std::string technique = default_technique_name();
    std::string sweep;                  // KNOB=V1,V2,...: one row per mesh and value
    std::vector<std::string> settings;  // key=value for every row
    std::string mesh;                   // default: the technique's comparison, or sphere
    std::vector<std::string> faces;
    std::string size = "512x512";
    int frames = 60;
    int warmup = 3;
    std::string csv;  // the table, machine-readable (empty: none)
};

// Writes the printed table's rows (first row: the column names) as CSV.
bool write_table_csv(const std::string& path,
                     const std::vector<std::vector<std::string>>& table) {
    try {
        common::write_file_atomically(path, true, [&](std::ostream& out) {
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

// One frame's GPU time: the sum of its passes but the bakes (precomputed, e.g. the AO).
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
            if (is_bake(plan.passes[p])) continue;
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

// The lines above every table: what was measured, on which GL, timed how.
void print_heading(const FrameBenchOptions& options, const RenderRequest& request,
                   gl::Context& context, bool gpu_timer) {
    const gl::GlInfo info = context.info();
    std::cout << "lucent bench frame: " << options.technique << " on " << options.mesh
              << " at " << request.width << "x" << request.height << ", median of "
              << options.frames << " frames after " << options.warmup << " warm-up\n"
              << "GL: " << info.renderer << " (" << info.version << ")\n"
              << "timing: "
              << (gpu_timer ? "GL timer queries (GL_TIME_ELAPSED), summed over passes"
                            : "wall time around glFinish per pass (no timer queries)")
              << "; bakes (the AO) precomputed, not in the frame\n";
}

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

// The --set assignments every row shares; nullopt, after saying why, when one is not
// key=value.
std::optional<std::vector<KnobAssignment>> fixed_settings(
    const FrameBenchOptions& options) {
    std::vector<KnobAssignment> fixed;
    try {
        for (const auto& setting : options.settings)
            fixed.push_back(parse_assignment(setting));
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: --set: " << e.what() << "\n";
        return std::nullopt;
    }
    return fixed;
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
    const bool per_unit =
        knob->kind == KnobKind::integer || knob->kind == KnobKind::scalar;
    const auto fixed = fixed_settings(options);
    if (!fixed) return kExitUsage;
    std::ostringstream table, breakdowns;
    std::vector<std::vector<std::string>> csv = {{"mesh", "faces", knob_name, "total_ms",
                                                  "fps", "costliest_pass", "pass_ms",
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
            request.settings = *fixed;
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
            std::snprintf(
                line, sizeof line, "%10zu %10s | %12.3f %8.2f | %-16s %10.3f | %12s\n",
                scene.mesh->face_count(), value.c_str(), total_ms, 1000.0 / total_ms,
                pass.c_str(), pass_ms, per_unit ? number(ms_per_unit).c_str() : "");
            table << line;
            breakdowns << "  " << scene.mesh->face_count() << " faces, " << knob_name
                       << "=" << value << ": " << sampler.breakdown() << "\n";
            csv.push_back({request.mesh, std::to_string(scene.mesh->face_count()), value,
                           number(total_ms), number(1000.0 / total_ms), pass,
                           number(pass_ms), per_unit ? number(ms_per_unit) : ""});
        }
    }
    print_heading(options, request, context, gpu_timer);
    std::cout << "every pass runs every frame (as when the light or material changes)\n\n"
              << table.str();
    if (per_unit)
        std::cout << "ms per unit = the costliest pass's median / " << knob_name << "\n";
    std::cout << "\nmedian per pass (ms):\n" << breakdowns.str();
    return finish_csv(options, csv);
}

// The technique's own comparison (Technique::frame_comparison): one row per mesh, each
// variant's median frame time and its ratio to the last variant.
int run_comparison_bench(const FrameBenchOptions& options,
                         const FrameComparison& comparison, RenderRequest request,
                         gl::Context& context) {
    const auto fixed = fixed_settings(options);
    if (!fixed) return kExitUsage;
    const auto& variants = comparison.variants;
    const std::string& baseline = variants.back().label;
    std::ostringstream table, breakdowns;
    std::vector<std::string> header = {"mesh", "faces", "vertices"};
    char line[256];
    std::snprintf(line, sizeof line, "%10s %10s |", "faces", "vertices");
    std::string heading = line;
    for (const auto& v : variants) {
        std::snprintf(line, sizeof line, " %12s %8s |", (v.label + " (ms)").c_str(),
                      "fps");
        heading += line;
        header.push_back(v.label + "_ms");
    }
    for (std::size_t v = 0; v + 1 < variants.size(); ++v) {
        std::snprintf(line, sizeof line, " %*s",
                      std::max<int>(6, static_cast<int>(variants[v].label.size() +
                                                        baseline.size() + 3)),
                      (variants[v].label + " / " + baseline).c_str());
        heading += line;
        header.push_back(variants[v].label + "_over_" + baseline);
    }
    table << heading << "\n" << std::string(heading.size(), '-') << "\n";
    std::vector<std::vector<std::string>> csv = {header};
    const Technique& technique = find_technique(options.technique);
    bool gpu_timer = false;
    for (const auto& faces : options.faces) {
        request.mesh = options.mesh + ":" + faces;
        std::vector<Scene> scenes;
        try {
            for (const auto& v : variants) {
                request.settings = *fixed;
                request.settings.insert(request.settings.end(), v.settings.begin(),
                                        v.settings.end());
                scenes.push_back(build_scene(request));
                scenes.back().mesh =
                    scenes.front().mesh;  // same mesh object: uploaded once
            }
        } catch (const std::exception& e) {
            std::cerr << "lucent bench frame: " << e.what() << "\n";
            return kExitUsage;
        }
        const Mesh& mesh = *scenes.front().mesh;
        std::cerr << "measuring " << request.mesh << " (" << mesh.face_count()
                  << " faces)...\n";
        // Frames alternate between the variants (one executor each, so none
        // reallocates), so all see the same load on a shared machine.
        std::vector<std::unique_ptr<Sampler>> samplers;
        for (const Scene& scene : scenes) {
            samplers.push_back(std::make_unique<Sampler>());
            samplers.back()->plan = make_frame_plan(scene, technique);
        }
        try {
            for (int i = 0; i < options.warmup + options.frames; ++i)
                for (std::size_t v = 0; v < variants.size(); ++v)
                    samplers[v]->run(scenes[v], i >= options.warmup);
        } catch (const std::exception& e) {
            std::cerr << "lucent bench frame: " << e.what() << "\n";
            return kExitFailure;
        }
        gpu_timer = samplers.front()->executor.last_timings().gpu_timer;
        std::vector<double> ms;
        for (const auto& sampler : samplers) ms.push_back(median(sampler->frame_ms));
        std::snprintf(line, sizeof line, "%10zu %10zu |", mesh.face_count(),
                      mesh.vertex_count());
        table << line;
        std::vector<std::string> row = {request.mesh, std::to_string(mesh.face_count()),
                                        std::to_string(mesh.vertex_count())};
        breakdowns << "  " << mesh.face_count() << " faces:";
        for (std::size_t v = 0; v < variants.size(); ++v) {
            std::snprintf(line, sizeof line, " %12.3f %8.1f |", ms[v], 1000.0 / ms[v]);
            table << line;
            row.push_back(number(ms[v]));
            breakdowns << (v ? " | " : " ") << variants[v].label << ": "
                       << samplers[v]->breakdown();
            if (comparison.detail)
                breakdowns << " (" << comparison.detail(scenes[v]) << ")";
        }
        for (std::size_t v = 0; v + 1 < variants.size(); ++v) {
            const std::string label = variants[v].label + " / " + baseline;
            std::snprintf(line, sizeof line, " %*.2f",
                          std::max<int>(6, static_cast<int>(label.size())),
                          ms[v] / ms.back());
            table << line;
            row.push_back(number(ms[v] / ms.back()));
        }
        table << "\n";
        breakdowns << "\n";
        csv.push_back(row);
    }
    std::string ratio_legend;
    for (std::size_t v = 0; v + 1 < variants.size(); ++v)
        ratio_legend += (v ? ", " : "ratio = ") + variants[v].label + " / " + baseline;
    ratio_legend += " frame time";
    print_heading(options, request, context, gpu_timer);
    std::cout << comparison.note << "\n\n"
              << table.str() << ratio_legend << "\n\n"
              << "median per pass (ms):\n"
              << breakdowns.str();
    return finish_csv(options, csv);
}

int run_frame_bench(FrameBenchOptions options, const std::vector<std::string>& given) {
    const auto was_given = [&](const char* option) {
        return std::find(given.begin(), given.end(), option) != given.end();
    };
    const Technique* technique = nullptr;
    try {
        technique = &find_technique(options.technique);
    } catch (const std::exception& e) {
        std::cerr << "lucent bench frame: --technique: " << e.what() << "\n";
        return kExitUsage;
    }
    const std::optional<FrameComparison> comparison =
        options.sweep.empty() ? technique->frame_comparison() : std::nullopt;
    // Defaults: the technique's comparison table, else a sweep at a size llvmpipe can do
    // in minutes (the dipole at N = 2500 costs seconds per 512x512 frame).
    if (comparison) {
        if (!was_given("--mesh")) options.mesh = comparison->mesh;
        if (!was_given("--faces")) options.faces = comparison->faces;
    } else {
        if (!was_given("--size")) options.size = "128x128";
        if (!was_given("--frames")) options.frames = 5;
        if (!was_given("--warmup")) options.warmup = 1;
        if (!was_given("--mesh")) options.mesh = "sphere";
        if (!was_given("--faces")) options.faces = {"2k", "10k", "30k"};
    }
    RenderRequest request;
    request.technique = options.technique;
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
    if (comparison) return run_comparison_bench(options, *comparison, request, *context);
    return run_sweep_bench(options, request, *context);
}

}  // namespace

void register_bench_frame(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<FrameBenchOptions>();
    auto* cmd =
        bench.add_subcommand("frame",
                             "Median GPU frame time per mesh: full empirical shader vs "
                             "direct light, or a technique's knob swept");
    cmd->add_option("--technique", options->technique,
                    "empirical: full vs direct light; another: rows of mesh x --sweep");
    cmd->add_option("--sweep", options->sweep,
                    "KNOB=V1,V2,...: one row per mesh and value (default for a technique "
                    "other than empirical: its first quality knob)");
    cmd->add_option(
        "--set", options->settings,
        "other parameters for every row of a --sweep, key=value (repeatable)");
    cmd->add_option("--mesh", options->mesh,
                    "built-in mesh family (face budgets from --faces)");
    cmd->add_option("--faces", options->faces, "face budgets, e.g. 4k 30k 60k 120k 240k")
        ->delimiter(',');
    cmd->add_option("--size", options->size, "frame size WxH");
    cmd->add_option("--frames", options->frames, "timed frames per row (median)");
    cmd->add_option("--warmup", options->warmup, "untimed frames first");
    cmd->add_option("--csv", options->csv,
                    "also write the table as CSV (columns as printed)");
    cmd->callback([options, cmd, &exit_code] {
        std::vector<std::string> given;
        for (const char* option : {"--size", "--frames", "--warmup", "--mesh", "--faces"})
            if (cmd->count(option) > 0) given.push_back(option);
        exit_code = run_frame_bench(*options, given);
    });
}

}  // namespace lucent::app
