// lucent bench accuracy: what each quality knob of a technique costs and buys. For every
// knob in Technique::quality_sweeps(), render the GL image at each value (the other
// quality knobs at their reference values), measure its error against the technique's
// CPU reference at the reference values (RMSE, 99th percentile, outside a 1-pixel
// silhouette band), its median GPU frame time, and the precomputation it needs (its
// bakes, e.g. the AO: uploads of ProductionCost::bake, timed uncached). Prints a table
// and writes an SVG of error vs time per knob. Techniques join by declaring
// quality_sweeps(); nothing here names a technique's knobs. A sweep of a scene knob
// (thick_texture's thickness and tilt) is measured against the reference of each of its
// values.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <map>
#include <sstream>

#include "app/commands.h"
#include "common/html/svg_plot.h"
#include "renderer/core/image_compare.h"
#include "renderer/gl/context.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"

namespace lucent::app {
namespace {

struct AccuracyBenchOptions {
    std::string technique = default_technique_name();
    std::string mesh = "torus_knot:30k";
    std::string size = "256x256";
    std::vector<std::string> settings;
    int frames = 30;
    std::string svg = "bench-accuracy.svg";
    std::string csv;  // the table, machine-readable (empty: none)
};

struct Row {
    std::string knob, value;
    ImageErrorStats error;
    double block_rmse = 0.0;  // RMSE of 4x4 block means (see block_mean_rmse)
    double frame_ms = 0.0;
    double precompute_s = 0.0;
    std::string pass_ms;  // "name=ms;..." median per pass, for the CSV
};

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
}

// RMSE of the differences of 4x4 block means (rgb) over blocks inside the object in both
// images: a texture's mip footprint is not a pixel box, so per-pixel RMSE overstates
// errors at texel scale that average out over a few pixels.
double block_mean_rmse(const Image& a, const Image& b, int k = 4) {
    double sum2 = 0.0;
    std::size_t blocks = 0;
    for (int by = 0; by + k <= a.height; by += k)
        for (int bx = 0; bx + k <= a.width; bx += k) {
            glm::dvec3 d(0.0);
            bool inside = true;
            for (int y = by; y < by + k && inside; ++y)
                for (int x = bx; x < bx + k; ++x) {
                    const glm::vec4 pa = a.at(x, y), pb = b.at(x, y);
                    if (pa.a <= 0.5f || pb.a <= 0.5f) inside = false;
                    d += glm::dvec3(pa) - glm::dvec3(pb);
                }
            if (!inside) continue;
            d /= double(k * k);
            sum2 += glm::dot(d, d) / 3.0;
            ++blocks;
        }
    return blocks ? std::sqrt(sum2 / double(blocks)) : 0.0;
}

double median_of(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

// Median GPU frame time (bakes excluded) and the median of each pass, as
// "name=ms;name=ms".
double median_frame_ms(gl::FrameExecutor& executor, const Scene& scene,
                       const FramePlan& plan, int frames,
                       std::string* pass_ms = nullptr) {
    std::vector<double> times;
    std::vector<std::vector<double>> per_pass(plan.passes.size());
    for (int i = 0; i < frames + 1; ++i) {  // the first frame warms caches
        executor.execute(scene, plan, true);
        double ms = 0.0;
        const auto& passes = executor.last_timings().passes;
        for (std::size_t p = 0; p < passes.size(); ++p)
            if (!is_bake(plan.passes[p])) {
                ms += passes[p].milliseconds;
                if (i > 0 && p < per_pass.size())
                    per_pass[p].push_back(passes[p].milliseconds);
            }
        if (i > 0) times.push_back(ms);
    }
    if (pass_ms) {
        pass_ms->clear();
        for (std::size_t p = 0; p < per_pass.size(); ++p) {
            if (per_pass[p].empty()) continue;
            char text[64];
            std::snprintf(text, sizeof text, "%.4g", median_of(per_pass[p]));
            *pass_ms += (pass_ms->empty() ? "" : ";") + plan.passes[p].name + "=" + text;
        }
    }
    return median_of(times);
}

// The knob's name, with the settings its sweep fixes: "rings (hybrid=on)".
std::string sweep_label(const QualitySweep& sweep) {
    std::string label = sweep.knob, fixed;
    for (const auto& [knob, value] : sweep.with)
        fixed += (fixed.empty() ? "" : " ") + knob + "=" + format_knob_value(value);
    return fixed.empty() ? label : label + " (" + fixed + ")";
}

// One panel per knob, wrapping three to a row: RMSE (y, a log axis where the errors span
// more than a decade) against the cost that varies along the sweep (x): the
// precomputation when it varies, otherwise the GPU frame time.
void write_svg(const std::string& path, const std::vector<Row>& rows,
               const std::string& title) {
    std::vector<common::PlotPanel> panels;
    for (const auto& r : rows)
        if (std::none_of(panels.begin(), panels.end(),
                         [&](const auto& p) { return p.title == r.knob; }))
            panels.emplace_back().title = r.knob;
    for (auto& panel : panels) {
        std::vector<const Row*> series;
        for (const auto& r : rows)
            if (r.knob == panel.title) series.push_back(&r);
        double min_pre = 1e300, max_pre = 0;
        for (const Row* r : series)
            min_pre = std::min(min_pre, r->precompute_s),
            max_pre = std::max(max_pre, r->precompute_s);
        const bool by_precompute = max_pre > 1.5 * std::max(min_pre, 1e-9);
        for (const Row* r : series) {
            panel.x.push_back(by_precompute ? r->precompute_s : r->frame_ms);
            panel.y.push_back(r->error.rmse);
            panel.point_labels.push_back(r->value);
        }
        panel.x_label = by_precompute ? "bake time (s)" : "GPU frame time (ms)";
        panel.y_label = "RMSE vs CPU reference";
        panel.x_axis.include_zero = panel.y_axis.include_zero = true;
        panel.y_axis.log_ratio = 10.0;  // errors over more than a decade: log
    }
    std::ofstream svg(path);
    svg << common::figure_svg(title, panels);
    if (!svg) throw std::runtime_error(path + ": cannot write the SVG plot");
}

std::string size_text(const Scene& scene) {
    return std::to_string(scene.width) + "x" + std::to_string(scene.height);
}

// The technique's CPU reference of `scene`. A reference larger than 64x64 says first
// how long it should take: the same scene at 16 pixels wide (a warm-up: the first call
// pays one-off costs), then timed at 32 and 64 wide, time ~ pixels^p with p fitted to
// those two (kept within [1, 3]: a reference may grow faster than its pixel count);
// then every 15 s while it runs its elapsed time and what is left, and its time at the
// end.
Image timed_reference(const Technique& technique, const Scene& scene,
                      const std::string& what) {
    const std::string size = size_text(scene);
    const double pixels = double(scene.width) * double(scene.height);
    if (pixels <= 64.0 * 64.0) {
        std::cerr << what << " at " << size << "...\n";
        return technique.render_reference(scene);
    }
    struct SmallRun {
        std::string size;
        double pixels, seconds;
    };
    const auto small_run = [&](int width) {
        Scene small = scene;
        fit_scene_camera(
            small, width,
            std::max(1, int(std::lround(double(width) * scene.height / scene.width))));
        const auto t0 = std::chrono::steady_clock::now();
        technique.render_reference(small);
        return SmallRun{size_text(small), double(small.width) * small.height,
                        seconds_since(t0)};
    };
    small_run(16);
    const SmallRun a = small_run(32), b = small_run(64);
    const double power =
        std::clamp(a.seconds > 0 && b.seconds > 0
                       ? std::log(b.seconds / a.seconds) / std::log(b.pixels / a.pixels)
                       : 1.0,
                   1.0, 3.0);
    const double expected = b.seconds * std::pow(pixels / b.pixels, power);
    char line[320];
    std::snprintf(line, sizeof line,
                  "%s at %s: expected ~%.1f s (from %s and %s runs in %.3f s and %.3f "
                  "s: time ~ pixels^%.2f)\n",
                  what.c_str(), size.c_str(), expected, a.size.c_str(), b.size.c_str(),
                  a.seconds, b.seconds, power);
    std::cerr << line;
    const auto start = std::chrono::steady_clock::now();
    auto pending =
        std::async(std::launch::async, [&] { return technique.render_reference(scene); });
    while (pending.wait_for(std::chrono::seconds(15)) != std::future_status::ready) {
        const double elapsed = seconds_since(start);
        if (elapsed < expected)
            std::snprintf(line, sizeof line,
                          "%s at %s: %.0f s elapsed, ~%.0f s left of ~%.0f s expected\n",
                          what.c_str(), size.c_str(), elapsed, expected - elapsed,
                          expected);
        else
            std::snprintf(line, sizeof line,
                          "%s at %s: %.0f s elapsed, longer than the ~%.0f s expected\n",
                          what.c_str(), size.c_str(), elapsed, expected);
        std::cerr << line;
    }
    Image image = pending.get();
    std::snprintf(line, sizeof line, "%s at %s: done in %.1f s (expected ~%.1f s)\n",
                  what.c_str(), size.c_str(), seconds_since(start), expected);
    std::cerr << line;
    return image;
}

int run_accuracy_bench(const AccuracyBenchOptions& options) {
    RenderRequest request;
    request.technique = options.technique;
    request.mesh = options.mesh;
    std::vector<QualitySweep> sweeps;
    Scene reference_scene;
    try {
        if (std::sscanf(options.size.c_str(), "%dx%d", &request.width, &request.height) !=
            2)
            throw std::invalid_argument("--size: '" + options.size + "' is not WxH");
        if (options.frames < 1)
            throw std::invalid_argument("--frames: must be at least 1");
        sweeps = find_technique(options.technique).quality_sweeps();
        if (sweeps.empty())
            throw std::invalid_argument("--technique: '" + options.technique +
                                        "' declares no quality knobs");
        for (const auto& s : options.settings)
            request.settings.push_back(parse_assignment(s));
        for (const auto& sweep : sweeps)  // scene knobs keep --set or their default
            if (!sweep.per_value_reference)
                request.settings.push_back(
                    {sweep.knob, format_knob_value(sweep.reference)});
        reference_scene = build_scene(request);
    } catch (const std::exception& e) {
        std::cerr << "lucent bench accuracy: " << e.what() << "\n";
        return kExitUsage;
    }
    const Technique& technique = find_technique(options.technique);
    std::unique_ptr<gl::Context> context;
    try {
        context = gl::create_headless_context();
    } catch (const std::exception& e) {
        std::cerr << "lucent bench accuracy: " << e.what() << "\n";
        return kExitFailure;
    }
    // Bakes (the AO) timed uncached, once per content hash (per ray count); the GL path
    // then uses those values.
    std::map<std::string, std::pair<TextureData, double>> bakes;
    const auto bake = [&](const Pass& pass) -> const std::pair<TextureData, double>& {
        auto it = bakes.find(pass.data.content_hash);
        if (it == bakes.end()) {
            std::cerr << "baking " << pass.name << " (" << pass.data.content_hash
                      << ")...\n";
            ProduceOptions uncached;
            uncached.use_caches = false;
            const auto start = std::chrono::steady_clock::now();
            TextureData data = pass.data.produce(uncached);
            it = bakes
                     .emplace(pass.data.content_hash,
                              std::make_pair(std::move(data), seconds_since(start)))
                     .first;
        }
        return it->second;
    };
    gl::FrameExecutor executor;
    executor.set_upload_producer([&](const Pass& pass) {
        return is_bake(pass) ? bake(pass).first : produce_upload(pass);
    });

    const auto reference_start = std::chrono::steady_clock::now();
    const Image reference = timed_reference(technique, reference_scene, "CPU reference");
    const double reference_s = seconds_since(reference_start);

    std::vector<Row> rows;
    try {
        for (const auto& sweep : sweeps)
            for (const auto& value : sweep.values) {
                RenderRequest row_request = request;
                for (const auto& [knob, fixed] : sweep.with)
                    row_request.settings.push_back({knob, format_knob_value(fixed)});
                row_request.settings.push_back({sweep.knob, format_knob_value(value)});
                Scene scene = reference_scene;
                scene.values =
                    resolve_knob_values(knobs_for(technique), row_request.settings);
                // Scene inputs made from knobs follow them (htsm's density_resolution).
                scene.density = density_from_knobs(scene.values);
                const FramePlan plan = make_frame_plan(scene, technique);
                Row row{sweep_label(sweep), format_knob_value(value)};
                // Scene knobs (h, angle): the reference of this scene, the other quality
                // knobs at their reference values.
                Image row_reference;
                if (sweep.per_value_reference) {
                    row_reference = timed_reference(technique, scene,
                                                    "CPU reference for " + sweep.knob +
                                                        "=" + format_knob_value(value));
                }
                const Image& truth =
                    sweep.per_value_reference ? row_reference : reference;
                row.frame_ms =
                    median_frame_ms(executor, scene, plan, options.frames, &row.pass_ms);
                Image image = executor.read_output(plan);
                replace_non_finite(image);
                row.error = compare_images(image, truth, 1);
                row.block_rmse = block_mean_rmse(image, truth);
                for (const auto& pass : plan.passes)
                    if (is_bake(pass)) row.precompute_s += bake(pass).second;
                rows.push_back(row);
            }
        write_svg(options.svg, rows,
                  "lucent bench accuracy: " + options.technique + " on " + options.mesh +
                      " at " + options.size);
    } catch (const std::exception& e) {
        std::cerr << "lucent bench accuracy: " << e.what() << "\n";
        return kExitFailure;
    }

    const gl::GlInfo info = context->info();
    std::cout << "lucent bench accuracy: " << options.technique << " on "
              << reference_scene.mesh->name << " (" << reference_scene.mesh->face_count()
              << " faces) at " << request.width << "x" << request.height
              << "\nGL: " << info.renderer << "; frame time = median of "
              << options.frames << " frames, "
              << (executor.last_timings().gpu_timer ? "GL timer queries"
                                                    : "glFinish wall time")
              << "; CPU reference (Embree, AO from the cache when present) took "
              << reference_s << " s\n"
              << "reference values:";
    for (const auto& sweep : sweeps)
        if (!sweep.per_value_reference)
            std::cout << " " << sweep.knob << "=" << format_knob_value(sweep.reference);
        else
            std::cout << " " << sweep.knob << " (each value against its own reference)";
    std::cout << "; error = GL image vs CPU reference outside a 1-pixel silhouette band, "
                 "linear rgb\n\n";
    char line[200];
    std::snprintf(line, sizeof line, "%-28s %9s | %10s %10s %10s %10s %10s | %9s %9s\n",
                  "knob", "value", "RMSE", "p99", "mean", "max", "block RMSE", "frame ms",
                  "bake s");
    std::cout << line << std::string(119, '-') << "\n";
    for (const auto& r : rows) {
        std::snprintf(line, sizeof line,
                      "%-28s %9s | %10.2e %10.2e %10.2e %10.2e %10.2e | %9.3f %9.3f\n",
                      r.knob.c_str(), r.value.c_str(), r.error.rmse, r.error.p99,
                      r.error.mean, r.error.max, r.block_rmse, r.frame_ms,
                      r.precompute_s);
        std::cout << line;
    }
    std::cout << "\nplot: " << options.svg << "\n";
    if (!options.csv.empty()) {
        // Columns named like the printed table, plus the median time of every pass.
        std::ofstream csv(options.csv, std::ios::binary);
        csv << "knob,value,rmse,p99,mean,max,block_rmse,frame_ms,bake_s,pass_ms\n";
        for (const auto& r : rows) {
            char text[256];
            std::snprintf(text, sizeof text, "%s,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,",
                          r.knob.c_str(), r.value.c_str(), r.error.rmse, r.error.p99,
                          r.error.mean, r.error.max, r.block_rmse, r.frame_ms,
                          r.precompute_s);
            csv << text << '"' << r.pass_ms << "\"\n";
        }
        if (!csv) {
            std::cerr << "lucent bench accuracy: --csv " << options.csv
                      << ": cannot write\n";
            return kExitFailure;
        }
        std::cout << "table: " << options.csv << "\n";
    }
    return kExitOk;
}

}  // namespace

void register_bench_accuracy(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<AccuracyBenchOptions>();
    auto* cmd = bench.add_subcommand(
        "accuracy", "Error vs time of each quality knob against the CPU reference");
    cmd->add_option("--technique", options->technique,
                    "technique whose quality knobs to sweep");
    cmd->add_option("--mesh", options->mesh,
                    "mesh (built-in name with face budget, or file)");
    cmd->add_option("--size", options->size, "image size WxH");
    cmd->add_option("--set", options->settings,
                    "other parameters, key=value (repeatable)");
    cmd->add_option("--frames", options->frames, "timed frames per row (median)");
    cmd->add_option("--svg", options->svg, "where to write the error-vs-time plot");
    cmd->add_option("--csv", options->csv,
                    "also write the table as CSV (columns as printed, plus per-pass ms)");
    cmd->callback([options, &exit_code] { exit_code = run_accuracy_bench(*options); });
}

}  // namespace lucent::app
