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
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "app/commands.h"
#include "common/html/html_page.h"
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

// One panel per knob: RMSE (y) against the cost that varies along the sweep (x): the
// precomputation when it varies, otherwise the GPU frame time.
void write_svg(const std::string& path, const std::vector<Row>& rows,
               const std::string& title) {
    std::vector<std::string> knobs;
    for (const auto& r : rows)
        if (std::find(knobs.begin(), knobs.end(), r.knob) == knobs.end())
            knobs.push_back(r.knob);
    const int panel_w = 320, panel_h = 260, margin = 50;
    std::ofstream svg(path);
    svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << panel_w * knobs.size()
        << "' height='" << panel_h + 40 << "' font-family='sans-serif' font-size='11'>\n"
        << "<rect width='100%' height='100%' fill='white'/>\n<text x='10' y='16' "
           "font-size='13'>"
        << common::text_escape(title) << "</text>\n";
    for (std::size_t k = 0; k < knobs.size(); ++k) {
        std::vector<const Row*> series;
        for (const auto& r : rows)
            if (r.knob == knobs[k]) series.push_back(&r);
        double min_pre = 1e300, max_pre = 0;
        for (const Row* r : series)
            min_pre = std::min(min_pre, r->precompute_s),
            max_pre = std::max(max_pre, r->precompute_s);
        const bool by_precompute = max_pre > 1.5 * std::max(min_pre, 1e-9);
        const auto x_of = [&](const Row* r) {
            return by_precompute ? r->precompute_s : r->frame_ms;
        };
        double max_x = 0, max_y = 0;
        for (const Row* r : series)
            max_x = std::max(max_x, x_of(r)), max_y = std::max(max_y, r->error.rmse);
        max_x = max_x > 0 ? max_x * 1.15 : 1;
        max_y = max_y > 0 ? max_y * 1.15 : 1;
        const int ox = static_cast<int>(k) * panel_w + margin, oy = 30 + panel_h - margin;
        const int w = panel_w - margin - 20, h = panel_h - margin - 20;
        const auto px = [&](double x) { return ox + x / max_x * w; };
        const auto py = [&](double y) { return oy - y / max_y * h; };
        svg << "<text x='" << ox << "' y='" << oy - h - 6 << "' font-weight='bold'>"
            << common::text_escape(knobs[k]) << "</text>\n"
            << "<line x1='" << ox << "' y1='" << oy << "' x2='" << ox + w << "' y2='"
            << oy << "' stroke='black'/>\n"
            << "<line x1='" << ox << "' y1='" << oy << "' x2='" << ox << "' y2='"
            << oy - h << "' stroke='black'/>\n"
            << "<text x='" << ox + w / 2 << "' y='" << oy + 30
            << "' text-anchor='middle'>"
            << (by_precompute ? "bake time (s)" : "GPU frame time (ms)") << ", max "
            << max_x / 1.15 << "</text>\n"
            << "<text x='" << ox - 8 << "' y='" << oy - h / 2
            << "' text-anchor='middle' transform='rotate(-90 " << ox - 36 << " "
            << oy - h / 2 << ")'>RMSE vs CPU reference (max " << max_y / 1.15
            << ")</text>\n";
        std::string points;
        for (const Row* r : series)
            points += std::to_string(px(x_of(r))) + "," +
                      std::to_string(py(r->error.rmse)) + " ";
        svg << "<polyline fill='none' stroke='steelblue' stroke-width='1.5' points='"
            << points << "'/>\n";
        for (const Row* r : series)
            svg << "<circle cx='" << px(x_of(r)) << "' cy='" << py(r->error.rmse)
                << "' r='3' fill='steelblue'/>"
                << "<text x='" << px(x_of(r)) + 5 << "' y='" << py(r->error.rmse) - 5
                << "'>" << common::text_escape(r->value) << "</text>\n";
    }
    svg << "</svg>\n";
    if (!svg) throw std::runtime_error(path + ": cannot write the SVG plot");
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

    std::cerr << "CPU reference...\n";
    const auto reference_start = std::chrono::steady_clock::now();
    const Image reference = technique.render_reference(reference_scene);
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
                    std::cerr << "CPU reference at " << sweep.knob << "="
                              << format_knob_value(value) << "...\n";
                    row_reference = technique.render_reference(scene);
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
