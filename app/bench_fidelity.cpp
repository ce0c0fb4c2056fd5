// lucent bench fidelity: every real-time technique against the path-traced truth. Per
// case (the thesis's knot and key light, the same back-lit, and a thin knot), the truth
// is traced once; each technique takes the truth's knobs it shares by name (the dipole
// and htsm: material, size, density) and fits its appearance knobs
// (Technique::fidelity_fit) by BOBYQA within --evaluations renders; the table gives the
// fitted values, the error (mean and 95th-percentile Delta E00 on object pixels, linear
// RMSE) and the frame time, then the same along each quality knob, and the truth's own
// error at fewer paths against its time. One SVG plots error against time, every
// technique a curve.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "app/bench_results.h"
#include "app/commands.h"
#include "common/html/svg_plot.h"
#include "common/output_file.h"
#include "renderer/core/common_knobs.h"
#include "renderer/gl/context.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "stimuli/fidelity/fidelity.h"

namespace lucent::app {
namespace {

struct FidelityOptions {
    std::string cases = "all";  // thesis, backlit, thin, or all
    std::string mesh = "torus_knot:30k";
    std::string material = "marble";
    std::string light;  // front or back: overrides the cases' lights
    int size = 96;
    int paths = 256;
    int evaluations = 60;
    std::vector<std::string> techniques;  // default: every technique but path
    std::string csv, svg;
};

struct Case {
    std::string name, description;
    std::vector<KnobAssignment> settings;
};

// The thesis's key light (renderer/core/presets/thesis.toml) and its back-lit
// counterpart.
const std::vector<KnobAssignment> kFrontLight = {
    {"light_direction", "0.4,0.6,1"}, {"light_ambient", "0.6"}, {"light_diffuse", "1"}};
const std::vector<KnobAssignment> kBackLight = {
    {"light_direction", "0.2,0.5,-1"}, {"light_ambient", "0.1"}, {"light_diffuse", "1"}};

std::vector<Case> cases_of(const FidelityOptions& o) {
    const auto lit = [&](const std::vector<KnobAssignment>& light) {
        if (o.light == "front") return kFrontLight;
        if (o.light == "back") return kBackLight;
        return light;
    };
    std::vector<Case> cases;
    const auto with = [&](std::string name, std::string description,
                          std::vector<KnobAssignment> light, const std::string& size_mm) {
        std::vector<KnobAssignment> settings = lit(light);
        settings.push_back({"material", o.material});
        settings.push_back({"model_size", size_mm});
        cases.push_back({std::move(name), std::move(description), std::move(settings)});
    };
    if (o.cases == "all" || o.cases == "thesis")
        with("thesis", "the thesis's knot (30 mm) and key light", kFrontLight, "30");
    if (o.cases == "all" || o.cases == "backlit")
        with("backlit", "the knot (30 mm) lit from behind and above", kBackLight, "30");
    if (o.cases == "all" || o.cases == "thin")
        with("thin", "the knot at 3 mm: parts thinner than a transport mean free path",
             kBackLight, "3");
    return cases;
}

std::string settings_text(const std::vector<KnobAssignment>& settings) {
    std::string text;
    for (const KnobAssignment& a : settings)
        text += (text.empty() ? "" : " ") + a.key + "=" + a.text;
    return text.empty() ? "-" : text;
}

void print_error_row(const char* label, const stimuli::ImageError& e, double ms,
                     const std::string& extra) {
    char time[32] = "-";
    if (std::isfinite(ms)) std::snprintf(time, sizeof time, "%.2f", ms);
    std::printf("  %-22s %8.2f %8.2f %9.4f %10s  %s\n", label, e.mean_delta_e,
                e.p95_delta_e, e.rmse, time, extra.c_str());
}

// A technique's curve: along the quality knob whose values change its error the most
// (the one that buys accuracy with time), in order of time; the fitted point alone for
// a technique without one.
common::PlotSeries curve_of(const stimuli::TechniqueFit& fit) {
    std::map<std::string, std::vector<const stimuli::QualityPoint*>> by_knob;
    for (const stimuli::QualityPoint& q : fit.quality) by_knob[q.knob].push_back(&q);
    const std::vector<const stimuli::QualityPoint*>* widest = nullptr;
    double widest_spread = -1.0;
    for (const auto& [knob, points] : by_knob) {
        double lo = INFINITY, hi = -INFINITY;
        for (const auto* q : points) {
            lo = std::min(lo, q->error.mean_delta_e);
            hi = std::max(hi, q->error.mean_delta_e);
        }
        if (hi - lo > widest_spread) {
            widest_spread = hi - lo;
            widest = &points;
        }
    }
    common::PlotSeries series{fit.technique, {fit.frame_ms}, {fit.error.mean_delta_e}};
    if (widest) {
        std::vector<const stimuli::QualityPoint*> points = *widest;
        std::sort(points.begin(), points.end(),
                  [](const auto* a, const auto* b) { return a->frame_ms < b->frame_ms; });
        series = {fit.technique + " (" + points.front()->knob + ")", {}, {}};
        for (const auto* q : points) {
            series.x.push_back(q->frame_ms);
            series.y.push_back(q->error.mean_delta_e);
        }
    }
    return series;
}

int run_bench_fidelity(const FidelityOptions& options) {
    const std::vector<Case> cases = cases_of(options);
    if (cases.empty() ||
        (!options.light.empty() && options.light != "front" && options.light != "back")) {
        std::cerr
            << "lucent bench fidelity: --case must be thesis, backlit, thin or all, "
               "--light front or back\n";
        return kExitUsage;
    }
    std::vector<const Technique*> techniques;
    try {
        if (options.techniques.empty()) {
            for (const Technique* t : all_techniques())
                if (t->name() != "path") techniques.push_back(t);
        } else {
            for (const std::string& name : options.techniques)
                techniques.push_back(&find_technique(name));
        }
    } catch (const KnobError& e) {
        std::cerr << "lucent bench fidelity: --techniques " << e.what() << "\n";
        return kExitUsage;
    }
    auto context = gl::create_headless_context();
    gl::FrameExecutor executor;
    BenchResults results;
    std::vector<common::PlotPanel> panels;
    std::printf(
        "bench fidelity: %dx%d, truth %d paths per pixel and channel, fits of at "
        "most %d renders (BOBYQA)\n",
        options.size, options.size, options.paths, options.evaluations);
    for (const Case& c : cases) {
        RenderRequest request;
        request.mesh = options.mesh;
        request.technique = "path";
        request.width = request.height = options.size;
        request.settings = c.settings;
        request.settings.push_back({"paths", std::to_string(options.paths)});
        Scene truth_scene;
        try {
            truth_scene = build_scene(request);
        } catch (const std::exception& e) {
            std::cerr << "lucent bench fidelity: " << e.what() << "\n";
            return kExitUsage;
        }
        std::fprintf(stderr, "%s: tracing the truth (%d paths)...\n", c.name.c_str(),
                     options.paths);
        const auto start = std::chrono::steady_clock::now();
        const EstimatedImage truth =
            *find_technique("path").render_estimate(truth_scene, {});
        const double truth_ms = std::chrono::duration<double, std::milli>(
                                    std::chrono::steady_clock::now() - start)
                                    .count();
        std::printf("\n%s: %s, %s, %s\n  truth: %s\n", c.name.c_str(),
                    c.description.c_str(), options.mesh.c_str(),
                    settings_text(c.settings).c_str(), truth.summary.c_str());
        std::printf("  %-22s %8s %8s %9s %10s  %s\n", "technique", "dE mean", "dE p95",
                    "RMSE", "frame ms", "fitted (or taken) values");
        common::PlotPanel panel;
        panel.title = c.name;
        panel.x_label = "time per image (ms)";
        panel.y_label = "mean Delta E00 to the truth";
        panel.x_axis.scale = common::AxisScale::log;
        panel.y_axis.scale = common::AxisScale::automatic;
        for (const Technique* technique : techniques) {
            std::fprintf(stderr, "%s: fitting %s...\n", c.name.c_str(),
                         std::string(technique->name()).c_str());
            stimuli::FitOptions fit_options;
            fit_options.max_evaluations = options.evaluations;
            const stimuli::TechniqueFit fit = stimuli::fit_to_truth(
                executor, *technique, truth_scene, truth.mean, fit_options);
            const std::string name = fit.technique;
            if (!fit.refused.empty()) {
                std::printf("  %-22s refused: %s\n", name.c_str(), fit.refused.c_str());
                continue;
            }
            print_error_row(
                name.c_str(), fit.error, fit.frame_ms,
                fit.fitted.empty() ? "nothing to fit" : settings_text(fit.fitted));
            // What it took from the truth beyond the scene (light, camera): the material.
            std::vector<KnobAssignment> material;
            for (const KnobAssignment& a : fit.taken)
                if (std::none_of(scene_knobs().begin(), scene_knobs().end(),
                                 [&](const Knob& k) { return k.name == a.key; }))
                    material.push_back(a);
            if (!material.empty())
                std::printf("  %-22s takes %s\n", "", settings_text(material).c_str());
            print_error_row(("  (defaults)"), fit.start_error, NAN, "before the fit");
            const std::string section = c.name + " " + name;
            results.add(section, "mean Delta E00", fit.error.mean_delta_e, "dE00");
            results.add(section, "p95 Delta E00", fit.error.p95_delta_e, "dE00");
            results.add(section, "RMSE", fit.error.rmse, "linear");
            results.add(section, "frame", fit.frame_ms, "ms");
            results.add(section, "mean Delta E00 at defaults",
                        fit.start_error.mean_delta_e, "dE00");
            results.add(section, "evaluations", fit.evaluations, "renders");
            for (const stimuli::QualityPoint& q : fit.quality) {
                const std::string label = "  " + q.knob + "=" + q.value;
                print_error_row(label.c_str(), q.error, q.frame_ms, "");
                results.add(section, q.knob + "=" + q.value + " mean Delta E00",
                            q.error.mean_delta_e, "dE00");
                results.add(section, q.knob + "=" + q.value + " frame", q.frame_ms, "ms");
            }
            panel.series.push_back(curve_of(fit));
        }
        // The truth's own price: fewer paths against the converged image.
        common::PlotSeries truth_curve{"path (paths)", {}, {}};
        for (const int paths : {1, 4, 16, 64}) {
            if (paths >= options.paths) break;
            request.settings.back() = {"paths", std::to_string(paths)};
            request.settings.push_back({"seed", "1"});
            const Scene scene = build_scene(request);
            request.settings.pop_back();
            const auto t0 = std::chrono::steady_clock::now();
            const Image image = find_technique("path").render_reference(scene);
            const double ms = std::chrono::duration<double, std::milli>(
                                  std::chrono::steady_clock::now() - t0)
                                  .count();
            const stimuli::ImageError e = stimuli::image_error(image, truth.mean);
            const std::string label = "path paths=" + std::to_string(paths);
            print_error_row(label.c_str(), e, ms, "(CPU, 2 threads)");
            results.add(c.name + " path",
                        "paths=" + std::to_string(paths) + " mean Delta E00",
                        e.mean_delta_e, "dE00");
            results.add(c.name + " path", "paths=" + std::to_string(paths) + " time", ms,
                        "ms");
            truth_curve.x.push_back(ms);
            truth_curve.y.push_back(e.mean_delta_e);
        }
        results.add(c.name + " path", "truth time", truth_ms, "ms");
        panel.series.push_back(truth_curve);
        panels.push_back(std::move(panel));
    }
    std::printf(
        "\nfitted: the technique's Technique::fidelity_fit knobs by BOBYQA from its "
        "defaults; frame ms: GPU time of one frame on this GL (bakes excluded); path "
        "rows: "
        "the truth itself at fewer paths (CPU time)\n");
    if (!options.csv.empty() && !results.write_csv(options.csv)) {
        std::cerr << "lucent bench fidelity: --csv: cannot write " << options.csv << "\n";
        return kExitFailure;
    }
    if (!options.svg.empty()) {
        try {
            common::write_file_atomically(options.svg, true, [&](std::ostream& out) {
                common::FigureLayout layout;
                layout.panel_height = 340;  // room for the legend under the axis
                out << common::figure_svg("Error against the path-traced truth, and time",
                                          panels, layout);
            });
        } catch (const std::exception& e) {
            std::cerr << "lucent bench fidelity: --svg: " << e.what() << "\n";
            return kExitFailure;
        }
        std::printf("wrote %s\n", options.svg.c_str());
    }
    return kExitOk;
}

}  // namespace

void register_bench_fidelity(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<FidelityOptions>();
    auto* cmd = bench.add_subcommand(
        "fidelity",
        "Every technique against the path-traced truth: fitted knobs, Delta E00 and "
        "frame time, along each quality knob, with an error-against-time SVG");
    cmd->add_option("--case", options->cases, "thesis, backlit, thin or all")
        ->capture_default_str();
    cmd->add_option("--mesh", options->mesh, "mesh of every case")->capture_default_str();
    cmd->add_option("--material", options->material,
                    "Jensen et al. 2001 material of the truth (and the dipole)")
        ->capture_default_str();
    cmd->add_option("--light", options->light,
                    "front (the thesis's key light) or back, for every case");
    cmd->add_option("--size", options->size, "image side in pixels")
        ->capture_default_str();
    cmd->add_option("--paths", options->paths, "the truth's paths per pixel and channel")
        ->capture_default_str();
    cmd->add_option("--evaluations", options->evaluations,
                    "renders per technique's fit (budget)")
        ->capture_default_str();
    cmd->add_option("--techniques", options->techniques,
                    "techniques to fit (default: all but path)")
        ->delimiter(',');
    cmd->add_option("--csv", options->csv, "also write every number to FILE");
    cmd->add_option("--svg", options->svg, "the error-against-time figure");
    cmd->callback([options, &exit_code] { exit_code = run_bench_fidelity(*options); });
}

}  // namespace lucent::app
