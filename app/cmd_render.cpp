// lucent render: one image of a mesh under a technique, with parameters from --set.
// The work itself is lucent::build_scene + render_image + write_image
// (renderer/render.h), the same path batch rendering and the explorer use.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <optional>

#include "app/commands.h"
#include "renderer/core/technique.h"
#include "renderer/gl/context.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "stimuli/batch_render.h"
#include "study/protocol.h"
#include "study/session/browser_pictures.h"
#include "study/session/stimulus_source.h"

namespace lucent::app {
namespace {

constexpr const char* technique_progress_label = "sample passes ";

struct RenderOptions {
    std::string mesh;
    // Knob-declared scene inputs (Knob::input_hash): --NAME VALUE, the same as --set
    // NAME=VALUE, by knob name.
    std::map<std::string, std::string> inputs;
    std::string technique = default_technique_name();
    std::vector<std::string> settings;
    std::string size = "512x512";
    std::string out;
    bool explain = false;
    std::string plan = "pruned";
    bool linear = false;
    // The technique's CPU reference (Embree) instead of the GL frame plan.
    bool reference = false;
    // Batch mode (stimuli/batch_render.h): a stimulus-set config or a built-in preset.
    std::string config;
    std::string preset;
    // A study's pictures for `lucent serve` (study/session/browser_pictures.h).
    std::string study;
    std::string study_preset;
    int jobs = 1;
    bool force = false;
};

// "WxH" -> (w, h); throws std::invalid_argument naming --size.
void parse_size(const std::string& text, int& width, int& height) {
    const auto x = text.find('x');
    try {
        std::size_t used_w = 0, used_h = 0;
        if (x == std::string::npos) throw std::invalid_argument("");
        width = std::stoi(text.substr(0, x), &used_w);
        height = std::stoi(text.substr(x + 1), &used_h);
        if (used_w != x || used_h != text.size() - x - 1) throw std::invalid_argument("");
    } catch (const std::exception&) {
        throw std::invalid_argument("--size: '" + text + "' is not WxH (e.g. 512x512)");
    }
}

int run_render(const RenderOptions& options) {
    RenderRequest request;
    PlanMode mode = PlanMode::pruned;
    Scene scene;
    try {
        parse_size(options.size, request.width, request.height);
        request.mesh = options.mesh;
        request.technique = options.technique;
        for (const auto& [name, value] : options.inputs)
            if (!value.empty()) request.settings.push_back({name, value});
        for (const auto& s : options.settings)
            request.settings.push_back(parse_assignment(s));
        if (options.plan == "full")
            mode = PlanMode::full;
        else if (options.plan != "pruned")
            throw std::invalid_argument("--plan: '" + options.plan +
                                        "' (accepted: pruned, full)");
        if (options.reference && mode == PlanMode::full)
            throw std::invalid_argument(
                "--plan: 'full' applies to GL renders, not to --reference");
        if (options.reference && options.out.empty())
            throw std::invalid_argument("--out: missing (--reference writes an image)");
        if (options.out.empty() && !options.explain)
            throw std::invalid_argument(
                "--out: missing (give --out FILE, or --explain to print the plan)");
        if (!options.out.empty() && !is_supported_image_path(options.out))
            throw std::invalid_argument(
                "--out: '" + options.out +
                "' has an unsupported extension (accepted: .exr, .png, .tif)");
        scene = build_scene(request);
    } catch (const KnobError& e) {
        std::cerr << "lucent render: " << e.what() << "\n";
        return kExitUsage;
    } catch (const MeshError& e) {
        std::cerr << "lucent render: --mesh " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent render: " << e.what() << "\n";
        return kExitUsage;
    }

    const Technique& technique = find_technique(scene.technique);
    if (options.explain) {
        const FramePlan plan = make_frame_plan(scene, technique, mode);
        std::cout << "plan for " << scene.mesh->name << " (" << scene.mesh->face_count()
                  << " faces) with " << technique.name() << " at " << scene.width << "x"
                  << scene.height << (mode == PlanMode::full ? ", full" : "") << ":\n"
                  << plan.explain();
        if (options.out.empty()) return kExitOk;
    }
    std::size_t non_finite = 0;
    std::string error_file;
    try {
        RenderedImage rendered;
        // A Monte Carlo technique (path) renders its estimate with the per-pixel standard
        // error, written beside the image; its GL plan only uploads the same mean.
        std::optional<EstimatedImage> estimate;
        if (mode == PlanMode::pruned) {
            ProduceOptions produce;
            produce.progress = [](std::size_t done, std::size_t total) {
                std::cerr << "\r" << technique_progress_label << done << "/" << total
                          << (done == total ? "\n" : "") << std::flush;
            };
            estimate = technique.render_estimate(scene, produce);
        }
        if (estimate) {
            rendered.image = std::move(estimate->mean);
            rendered.non_finite_pixels =
                count_non_finite_pixels(rendered.image) +
                count_non_finite_pixels(estimate->standard_error);
            replace_non_finite(rendered.image);
            replace_non_finite(estimate->standard_error);
            std::filesystem::path errors(options.out);
            errors.replace_extension(".stderr.exr");
            error_file = errors.string();
            ImageWriteOptions linear;
            linear.linear = true;
            write_image(error_file, estimate->standard_error, linear);
            std::cout << estimate->summary << "\n";
        } else if (options.reference) {
            // The same scene, knobs and outputs; the ground truth a GL render is
            // measured against (no GL context needed).
            rendered.image = technique.render_reference(scene);
            rendered.non_finite_pixels = count_non_finite_pixels(rendered.image);
            replace_non_finite(rendered.image);
        } else {
            auto context = gl::create_headless_context();
            gl::FrameExecutor executor;
            rendered = render_image_counted(executor, scene, mode);
        }
        ImageWriteOptions write;
        write.linear = options.linear;
        write_image(options.out, rendered.image, write);
        non_finite = rendered.non_finite_pixels;
    } catch (const std::exception& e) {
        std::cerr << "lucent render: " << e.what() << "\n";
        return kExitFailure;
    }
    std::cout << "wrote " << options.out << (options.reference ? " (CPU reference)" : "")
              << (error_file.empty() ? "" : " and its standard error " + error_file)
              << "\n";
    // The file is valid (values replaced), but NaN/Inf means a rendering bug: say so and
    // fail, so scripts notice.
    if (non_finite > 0) {
        std::cerr << "lucent render: warning: " << non_finite << " pixels of "
                  << options.out
                  << " had NaN or Inf values (written as 0 or the largest float)\n";
        return kExitFailure;
    }
    return kExitOk;
}

std::string study_preset_list() {
    std::string names;
    for (const std::string& name : study::builtin_protocol_names())
        names += (names.empty() ? "" : ", ") + name;
    return names;
}

// The pictures of a study for the browser; a protocol or series problem is one line
// (exit 2, nothing written).
StimulusSet study_picture_set(const std::string& file, const std::string& preset) {
    try {
        return study::browser_picture_set(preset.empty()
                                              ? study::load_protocol_file(file)
                                              : study::builtin_protocol(preset));
    } catch (const study::ProtocolError& e) {
        throw StimulusSetError(e.what());
    } catch (const study::StimulusError& e) {
        throw StimulusSetError(e.what());
    }
}

bool is_builtin_study(const std::string& name) {
    const std::vector<std::string> studies = study::builtin_protocol_names();
    return std::find(studies.begin(), studies.end(), name) != studies.end();
}

// `render --preset NAME`: one name, one folder that `lucent run|serve --preset NAME
// --images DIR` shows. The built-in stimulus set NAME (its factor series, for the
// report), and when NAME is also a built-in study, every other picture that study shows:
// its adjust series and staircase ladders (study/web_series.h). A picture of both must
// be the same render, or the study would check its folder against another picture.
StimulusSet preset_picture_set(const std::string& name) {
    StimulusSet set = load_set_preset(name, default_set_catalog());
    if (!is_builtin_study(name)) return set;
    const StimulusSet shown = study_picture_set("", name);
    const std::string where = "--preset " + name + ": ";
    if (shown.width != set.width || shown.height != set.height)
        throw StimulusSetError(
            where +
            "the stimulus set's resolution differs from the study's stimulus_size");
    std::map<std::string, const Stimulus*> by_id;
    for (const Stimulus& s : set.stimuli) by_id[s.id] = &s;
    for (const Stimulus& picture : shown.stimuli) {
        const auto it = by_id.find(picture.id);
        if (it == by_id.end()) {
            set.stimuli.push_back(picture);
            continue;
        }
        const Stimulus& own = *it->second;
        if (own.technique != picture.technique || own.mesh != picture.mesh ||
            own.values.all() != picture.values.all())
            throw StimulusSetError(
                where + "stimulus '" + picture.id +
                "' of the stimulus set differs from the built-in study's");
    }
    return set;
}

}  // namespace

void register_render(CLI::App& app, int& exit_code) {
    auto options = std::make_shared<RenderOptions>();
    auto* cmd = app.add_subcommand("render",
                                   "Render one image of a mesh, or a stimulus set from a "
                                   "config or preset (headless)");
    std::string meshes;
    for (const auto& name : builtin_mesh_names())
        meshes += (meshes.empty() ? "" : ", ") + name;
    std::string techniques, keys;
    for (const Technique* t : all_techniques()) {
        techniques += (techniques.empty() ? "" : ", ") + std::string(t->name());
        for (const Knob& k : knobs_for(*t)) keys += (keys.empty() ? "" : ", ") + k.name;
    }
    cmd->add_option("--mesh", options->mesh,
                    "built-in mesh (" + meshes +
                        "; optional face budget, e.g. torus_knot:60k) or a mesh file");
    cmd->add_option("config", options->config,
                    "stimulus-set config (TOML): render every stimulus into --out DIR");
    std::string presets;
    for (const std::string& name : set_preset_names())
        presets += (presets.empty() ? "" : ", ") + name;
    cmd->add_option(
        "--preset", options->preset,
        "built-in set NAME (" + presets +
            ") into --out DIR: every picture 'lucent run|serve --preset NAME' "
            "shows; for a built-in study (" +
            study_preset_list() + ") its adjust series and staircase ladders too");
    cmd->add_option("--study", options->study,
                    "study protocol (TOML) of your own: every picture 'lucent serve' "
                    "shows, the adjust series and staircase ladders included, into --out "
                    "DIR");
    // The old name of --preset for a built-in study; hidden, it means nothing else.
    cmd->add_option("--study-preset", options->study_preset,
                    "the same as --preset NAME for a built-in study")
        ->group("");
    cmd->add_option("--jobs", options->jobs,
                    "stimulus sets: parallel workers (default 1)");
    cmd->add_flag("--force", options->force,
                  "stimulus sets: re-render unchanged stimuli too");
    // A scene input a knob declares (a density volume) gets an option of its own.
    std::map<std::string, std::string> input_users;
    for (const Technique* t : all_techniques())
        for (const Knob& k : t->knobs())
            if (k.input_hash) {
                std::string& users = input_users[k.name];
                if (users.empty())
                    users = k.description + " (the same as --set " + k.name + "=...; ";
                else
                    users += ", ";
                users += std::string(t->name());
            }
    for (const auto& [name, help] : input_users)
        cmd->add_option("--" + name, options->inputs[name], help + ")");
    cmd->add_option("--technique", options->technique, "technique (" + techniques + ")");
    cmd->add_option(
        "--set", options->settings,
        "parameter key=value, repeatable; rgb as r,g,b or one grey value (keys: " + keys +
            ")");
    cmd->add_option("--size", options->size, "image size WxH (default 512x512)");
    cmd->add_option("--out", options->out,
                    "output image: .exr (linear float), .png (8-bit), .tif (16-bit)");
    cmd->add_flag("--explain", options->explain,
                  "print the frame plan, one pass per line");
    cmd->add_option("--plan", options->plan,
                    "pruned (default) or full: run every pass, to check pruning");
    cmd->add_flag("--linear", options->linear, "write .png/.tif without sRGB encoding");
    cmd->add_flag(
        "--reference", options->reference,
        "render the technique's CPU reference (Embree) instead of the GL image: "
        "same scene, parameters and outputs");
    cmd->callback([options, &exit_code] {
        // One image (--mesh), a stimulus set (CONFIG), a built-in set (--preset, its
        // study's series included) or a study's pictures (--study), one of them.
        const int sources = !options->config.empty() + !options->preset.empty() +
                            !options->study.empty() + !options->study_preset.empty();
        const bool batch = sources > 0;
        const bool both = sources > 1;
        if (batch && options->reference) {
            std::cerr << "lucent render: --reference renders one image (--mesh), not a "
                         "stimulus set\n";
            exit_code = kExitUsage;
        } else if (batch && (!options->mesh.empty() || both)) {
            std::cerr
                << "lucent render: give one of --mesh, CONFIG, --preset or --study\n";
            exit_code = kExitUsage;
        } else if (!options->study.empty()) {
            exit_code = stimuli::run_render_set_command(
                [options] { return study_picture_set(options->study, ""); }, options->out,
                options->jobs, options->force);
        } else if (!options->preset.empty() || !options->study_preset.empty()) {
            exit_code = stimuli::run_render_set_command(
                [options] {
                    const std::string& name =
                        options->preset.empty() ? options->study_preset : options->preset;
                    // --study-preset names a built-in study.
                    if (options->preset.empty() && !is_builtin_study(name))
                        throw StimulusSetError("unknown preset '" + name +
                                               "' (valid: " + study_preset_list() + ")");
                    return preset_picture_set(name);
                },
                options->out, options->jobs, options->force);
        } else if (batch) {
            exit_code = stimuli::run_render_set_command(options->config, "", options->out,
                                                        options->jobs, options->force);
        } else if (options->mesh.empty()) {
            std::cerr << "lucent render: --mesh is required (or a stimulus-set CONFIG or "
                         "--preset)\n";
            exit_code = kExitUsage;
        } else {
            exit_code = run_render(*options);
        }
    });
}

}  // namespace lucent::app
