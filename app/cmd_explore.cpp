// lucent explore: the interactive explorer window (stimuli/explorer/). This file only
// turns the command line into an ExplorerSession and runs the window.
#include <iostream>

#include "commands.h"
#include "core/mesh.h"
#include "explorer/explorer.h"
#include "gl/context.h"
#include "stimulus_set.h"

namespace lucent::app {
namespace {

struct ExploreOptions {
    std::string mesh;
    std::string config;
    std::string technique;
    std::vector<std::string> settings;
    std::string size = "1280x720";
    int frames = 0;
    std::string screenshot;
    bool developer = false;
};

int run_explore(const ExploreOptions& options) {
    explorer::ExplorerSession session;
    explorer::ExplorerOptions window;
    try {
        if (!options.config.empty()) session = explorer::session_from_config(options.config);
        if (!options.mesh.empty()) session.mesh = options.mesh;
        if (!options.technique.empty())
            for (auto& set : session.sets) set.set_technique(options.technique);
        std::vector<KnobAssignment> assignments;
        for (const auto& s : options.settings) assignments.push_back(parse_assignment(s));
        for (auto& set : session.sets) set.apply(assignments);
        const auto x = options.size.find('x');
        std::size_t used_w = 0, used_h = 0;
        if (x == std::string::npos) throw std::invalid_argument("");
        try {
            window.width = std::stoi(options.size.substr(0, x), &used_w);
            window.height = std::stoi(options.size.substr(x + 1), &used_h);
        } catch (const std::exception&) {
            used_w = 0;
        }
        if (used_w != x || used_h != options.size.size() - x - 1 || window.width < 64 ||
            window.height < 64 || window.width > 8192 || window.height > 8192)
            throw std::invalid_argument("--size: '" + options.size +
                                        "' is not WxH with each in [64, 8192] (e.g. 1280x720)");
        if (options.frames < 0) throw std::invalid_argument("--frames: must be >= 0");
        session.developer_mode = options.developer;
    } catch (const KnobError& e) {
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitUsage;
    } catch (const stimuli::StimulusSetError& e) {
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent explore: "
                  << (*e.what() ? e.what() : "--size: expected WxH (e.g. 1280x720)") << "\n";
        return kExitUsage;
    }
    try {
        explorer::Explorer app(std::move(session), window);
        if (options.developer) app.reload_shaders();
        explorer::run_explorer(app, options.frames);
        if (!options.screenshot.empty()) {
            app.request_screenshot(options.screenshot);
            app.step();
            std::cout << "wrote " << options.screenshot << "\n";
        }
        const auto t = app.frame_times();
        std::cout << "frame ms over the last second: min " << t.min_ms << " mean " << t.mean_ms
                  << " max " << t.max_ms << " (" << t.frames << " frames, " << app.mesh().face_count()
                  << " faces)\n";
    } catch (const MeshError& e) {
        std::cerr << "lucent explore: --mesh " << e.what() << "\n";
        return kExitUsage;
    } catch (const gl::ContextError& e) {
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace

void register_explore(CLI::App& app, int& exit_code) {
    auto options = std::make_shared<ExploreOptions>();
    auto* cmd = app.add_subcommand("explore", "Interactive window to find stimulus parameters by eye");
    cmd->add_option("--mesh", options->mesh, "built-in mesh (e.g. torus_knot:240k) or a mesh file");
    cmd->add_option("--config", options->config,
                    "stimulus-set config: start from its first stimulus; \"Add to stimulus set\" appends to it");
    cmd->add_option("--technique", options->technique, "technique to start with");
    cmd->add_option("--set", options->settings, "starting parameter key=value, repeatable");
    cmd->add_option("--size", options->size, "window size WxH (default 1280x720)");
    cmd->add_option("--frames", options->frames, "quit after N frames and print frame times (0: run until closed)");
    cmd->add_option("--screenshot", options->screenshot, "write the window as PNG before quitting");
    cmd->add_flag("--dev", options->developer, "developer mode: shaders from LUCENT_SHADER_DIR (default: the source tree), reload button");
    cmd->callback([options, &exit_code] { exit_code = run_explore(*options); });
}

}  // namespace lucent::app
