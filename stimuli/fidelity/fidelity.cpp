#include "stimuli/fidelity/fidelity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlopt.hpp>
#include <stdexcept>

#include "renderer/core/display_transform.h"
#include "renderer/render.h"
#include "stimuli/set_report/colour_difference.h"

namespace lucent::stimuli {
namespace {

// The image as a display shows it: linear rgb clamped and sRGB-encoded, 3 per pixel.
std::vector<float> displayed(const Image& image) {
    std::vector<float> rgb(std::size_t(image.width) * image.height * 3);
    for (std::size_t i = 0, n = rgb.size() / 3; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = display_value(image.rgba[i * 4 + c]);
    return rgb;
}

// One fitted parameter: a knob's channel (rgb) or the knob.
struct Parameter {
    std::string knob;
    int channel = -1;  // -1: scalar or integer
    double lo = 0.0, hi = 1.0;
};

std::vector<Parameter> parameters_of(const Technique& technique) {
    const std::vector<Knob> knobs = knobs_for(technique);
    std::vector<Parameter> parameters;
    for (const FitRange& range : technique.fidelity_fit()) {
        const auto knob = std::find_if(knobs.begin(), knobs.end(), [&](const Knob& k) {
            return k.name == range.knob;
        });
        if (knob == knobs.end())
            throw std::logic_error(std::string(technique.name()) +
                                   ": fidelity_fit names '" + range.knob +
                                   "', which is not one of its knobs");
        if (knob->kind == KnobKind::rgb)
            for (int c = 0; c < 3; ++c)
                parameters.push_back({range.knob, c, range.lo, range.hi});
        else
            parameters.push_back({range.knob, -1, range.lo, range.hi});
    }
    return parameters;
}

std::string number_text(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

// The assignments for parameter values `x` (rgb knobs joined from their channels).
std::vector<KnobAssignment> assignments(const std::vector<Parameter>& parameters,
                                        const std::vector<double>& x) {
    std::vector<KnobAssignment> out;
    for (std::size_t i = 0; i < parameters.size(); ++i) {
        const Parameter& p = parameters[i];
        if (p.channel <= 0)
            out.push_back({p.knob, number_text(x[i])});
        else
            out.back().text += "," + number_text(x[i]);
    }
    return out;
}

// The technique's own value of each parameter in `scene`, clamped to its range.
std::vector<double> start_of(const std::vector<Parameter>& parameters,
                             const Scene& scene) {
    std::vector<double> x;
    for (const Parameter& p : parameters) {
        const KnobValue& value = scene.values.get(p.knob);
        double v = p.lo;
        if (const auto* rgb = std::get_if<glm::dvec3>(&value))
            v = (*rgb)[p.channel];
        else if (const auto* scalar = std::get_if<double>(&value))
            v = *scalar;
        else if (const auto* integer = std::get_if<int>(&value))
            v = *integer;
        x.push_back(std::clamp(v, p.lo, p.hi));
    }
    return x;
}

}  // namespace

ImageError image_error(const Image& image, const Image& truth) {
    if (image.width != truth.width || image.height != truth.height)
        throw std::invalid_argument("image_error: the images differ in size");
    const std::size_t pixels = std::size_t(truth.width) * truth.height;
    std::vector<std::uint8_t> mask(pixels);
    double squares = 0.0;
    ImageError error;
    for (std::size_t i = 0; i < pixels; ++i) {
        mask[i] = image.rgba[i * 4 + 3] > 0.5f || truth.rgba[i * 4 + 3] > 0.5f;
        if (!mask[i]) continue;
        ++error.pixels;
        for (int c = 0; c < 3; ++c) {
            const double d = double(image.rgba[i * 4 + c]) - truth.rgba[i * 4 + c];
            squares += std::isfinite(d) ? d * d : 0.0;
        }
    }
    const SrgbToLab to_lab;
    const DeltaEStatistics de = delta_e_statistics(
        to_lab.convert(displayed(image)), to_lab.convert(displayed(truth)), mask);
    error.mean_delta_e = de.mean;
    error.p95_delta_e = de.percentile_95;
    error.rms_delta_e = de.root_mean_square;
    error.rmse = error.pixels ? std::sqrt(squares / (3.0 * double(error.pixels))) : 0.0;
    return error;
}

Scene scene_like(const Scene& truth_scene, const Technique& technique,
                 const std::vector<KnobAssignment>& settings,
                 std::vector<KnobAssignment>* taken) {
    const std::vector<Knob> knobs = knobs_for(technique);
    std::vector<KnobAssignment> all;
    for (const Knob& knob : knobs) {
        if (!truth_scene.values.contains(knob.name)) continue;
        const KnobValue& value = truth_scene.values.get(knob.name);
        try {
            validate_knob_value(knob, value);
        } catch (const KnobError&) {
            continue;  // the same name with another range or kind: not the same quantity
        }
        all.push_back({knob.name, format_knob_value(value)});
    }
    if (taken) *taken = all;
    all.insert(all.end(), settings.begin(), settings.end());
    Scene scene = make_scene(truth_scene.mesh, technique, resolve_knob_values(knobs, all),
                             truth_scene.width, truth_scene.height);
    technique.check_scene(scene);
    return scene;
}

double frame_milliseconds(const Scene& scene, int frames) {
    const Technique& technique = find_technique(scene.technique);
    const FramePlan plan = make_frame_plan(scene, technique);
    std::vector<double> times;
    for (int f = 0; f < frames; ++f) {
        gl::FrameExecutor executor;
        executor.execute(scene, plan, /*time_passes=*/true);
        const gl::FrameTimings& timings = executor.last_timings();
        double ms = 0.0;
        for (std::size_t p = 0; p < timings.passes.size(); ++p)
            if (!is_bake(plan.passes[p])) ms += timings.passes[p].milliseconds;
        times.push_back(ms);
    }
    std::sort(times.begin(), times.end());
    return times.empty() ? 0.0 : times[times.size() / 2];
}

TechniqueFit fit_to_truth(gl::FrameExecutor& executor, const Technique& technique,
                          const Scene& truth_scene, const Image& truth,
                          const FitOptions& options) {
    TechniqueFit fit;
    fit.technique = std::string(technique.name());
    Scene start;
    try {
        start = scene_like(truth_scene, technique, {}, &fit.taken);
    } catch (const std::exception& e) {
        fit.refused = e.what();
        return fit;
    }
    const auto error_of = [&](const std::vector<KnobAssignment>& settings) {
        const Scene scene = scene_like(truth_scene, technique, settings);
        Image image = render_image(executor, scene);
        const ImageError error = image_error(image, truth);
        return std::pair{error, std::move(image)};
    };
    const std::vector<Parameter> parameters = parameters_of(technique);
    auto [start_error, start_image] = error_of({});
    fit.start_error = fit.error = start_error;
    fit.image = std::move(start_image);
    fit.evaluations = 1;
    if (!parameters.empty() && options.max_evaluations > 1) {
        const std::size_t n = parameters.size();
        std::vector<double> x = start_of(parameters, start), lo(n), hi(n), step(n);
        for (std::size_t i = 0; i < n; ++i) {
            lo[i] = parameters[i].lo;
            hi[i] = parameters[i].hi;
            step[i] = 0.25 * (hi[i] - lo[i]);
        }
        // BOBYQA (Powell 2009): bounded, derivative-free, a quadratic model from 2n + 1
        // points; the objective is a render, so its budget is counted in renders.
        nlopt::opt optimiser(nlopt::LN_BOBYQA, unsigned(n));
        optimiser.set_lower_bounds(lo);
        optimiser.set_upper_bounds(hi);
        optimiser.set_initial_step(step);
        optimiser.set_maxeval(options.max_evaluations - 1);
        optimiser.set_xtol_rel(1e-6);
        std::vector<double> best_x = x;
        double best = fit.error.rms_delta_e;
        struct Context {
            std::function<double(const std::vector<double>&)> objective;
        } context{[&](const std::vector<double>& at) {
            auto [error, image] = error_of(assignments(parameters, at));
            ++fit.evaluations;
            if (options.progress)
                options.progress(fit.evaluations, options.max_evaluations);
            if (error.rms_delta_e < best) {
                best = error.rms_delta_e;
                best_x = at;
                fit.error = error;
                fit.image = std::move(image);
            }
            return error.rms_delta_e;
        }};
        optimiser.set_min_objective(
            [](const std::vector<double>& at, std::vector<double>&, void* data) {
                return static_cast<Context*>(data)->objective(at);
            },
            &context);
        double minimum = 0.0;
        try {
            optimiser.optimize(x, minimum);
        } catch (const std::exception&) {
            // NLopt stops on round-off or a forced stop: the best point so far stands.
        }
        fit.fitted = assignments(parameters, best_x);
    }
    const Scene fitted = scene_like(truth_scene, technique, fit.fitted);
    fit.frame_ms = frame_milliseconds(fitted);
    for (const QualitySweep& sweep : technique.quality_sweeps())
        for (const KnobValue& value : sweep.values) {
            std::vector<KnobAssignment> settings = fit.fitted;
            for (const auto& [knob, with] : sweep.with)
                settings.push_back({knob, format_knob_value(with)});
            settings.push_back({sweep.knob, format_knob_value(value)});
            try {
                const Scene scene = scene_like(truth_scene, technique, settings);
                const ImageError error =
                    image_error(render_image(executor, scene), truth);
                fit.quality.push_back({sweep.knob, format_knob_value(value), error,
                                       frame_milliseconds(scene)});
            } catch (const KnobError&) {
                // a value the fitted scene cannot take (none today): left out
            }
        }
    return fit;
}

}  // namespace lucent::stimuli
