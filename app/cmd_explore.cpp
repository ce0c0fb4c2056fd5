// lucent explore: the interactive explorer window (stimuli/explorer/). This file only
// turns the command line into an ExplorerSession and runs the window.
#include <iostream>

#include "app/commands.h"
#include "renderer/core/image.h"
#include "renderer/core/mesh.h"
#include "renderer/core/stimulus_set.h"
#include "stimuli/explorer/explorer.h"
#include "stimuli/explorer/frame_stats.h"

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

// "WxH" with each side in [64, 8192]; throws std::invalid_argument naming --size.
void parse_window_size(const std::string& text, int& width, int& height) {
    const auto x = text.find('x');
    std::size_t used_w = 0, used_h = 0;
    try {
        if (x == std::string::npos) throw std::invalid_argument("");
        width = std::stoi(text.substr(0, x), &used_w);
        height = std::stoi(text.substr(x + 1), &used_h);
    } catch (const std::exception&) {
        used_w = used_h = 0;
    }
    if (x == std::string::npos || used_w != x || used_h != text.size() - x - 1 ||
        width < 64 || height < 64 || width > 8192 || height > 8192)
        throw std::invalid_argument(
            "--size: '" + text + "' is not WxH with each in [64, 8192] (e.g. 1280x720)");
}

int run_explore(const ExploreOptions& options) {
    explorer::ExplorerSession session;
    explorer::ExplorerOptions window;
    try {
        if (!options.config.empty())
            session = explorer::session_from_config(options.config);
        if (!options.mesh.empty()) session.mesh = options.mesh;
        if (!options.technique.empty())
            for (auto& set : session.sets) set.set_technique(options.technique);
        std::vector<KnobAssignment> assignments;
        for (const auto& s : options.settings) assignments.push_back(parse_assignment(s));
        for (auto& set : session.sets) set.apply(assignments);
        parse_window_size(options.size, window.width, window.height);
        if (options.frames < 0) throw std::invalid_argument("--frames: must be >= 0");
        if (!options.screenshot.empty() && !is_supported_image_path(options.screenshot))
            throw std::invalid_argument(
                "--screenshot: '" + options.screenshot +
                "' has an unsupported extension (accepted: .png, .tif, .exr)");
        session.developer_mode = options.developer;
    } catch (const KnobError& e) {
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitUsage;
    } catch (const StimulusSetError& e) {
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitUsage;
    }
    try {
        explorer::Explorer app(std::move(session), window);
        if (options.developer) app.reload_shaders();
        // Frames that wait for an AO bake draw only the panels; they are not counted.
        explorer::FrameStats rendered(1e12);
        for (int counted = 0;
             !app.should_close() && (options.frames == 0 || counted < options.frames);) {
            app.step();
            if (!app.ambient_occlusion_pending() && app.shown().valid)
                rendered.add(counted++, app.last_frame_ms());
        }
        if (!options.screenshot.empty()) {
            app.request_screenshot(options.screenshot);
            app.step();
            std::cout << "wrote " << options.screenshot << "\n";
        }
        const auto all = rendered.summary(), last = app.frame_times();
        std::cout << "frame ms (" << window.width << "x" << window.height << ", "
                  << app.mesh().face_count() << " faces, " << all.frames
                  << " rendered frames): min " << all.min_ms << " mean " << all.mean_ms
                  << " max " << all.max_ms << "; last second: min " << last.min_ms
                  << " mean " << last.mean_ms << " max " << last.max_ms << "\n";
    } catch (const MeshError& e) {
        std::cerr << "lucent explore: --mesh " << e.what() << "\n";
        return kExitUsage;
    } catch (
        const std::exception& e) {  // no window (gl::ContextError), GL or I/O failure
        std::cerr << "lucent explore: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace

void register_explore(CLI::App& app, int& exit_code) {
    auto options = std::make_shared<ExploreOptions>();
    auto* cmd = app.add_subcommand(
        "explore", "Interactive window to find stimulus parameters by eye");
    cmd->add_option("--mesh", options->mesh,
                    "built-in mesh (e.g. torus_knot:240k) or a mesh file");
    cmd->add_option("--config", options->config,
                    "stimulus-set config: start from its first stimulus; \"Add to "
                    "stimulus set\" appends to it");
    cmd->add_option("--technique", options->technique, "technique to start with");
    cmd->add_option("--set", options->settings,
                    "starting parameter key=value, repeatable");
    cmd->add_option("--size", options->size, "window size WxH (default 1280x720)");
    cmd->add_option("--frames", options->frames,
                    "quit after N frames and print frame times (0: run until closed)");
    cmd->add_option("--screenshot", options->screenshot,
                    "write the window as PNG before quitting");
    cmd->add_flag("--dev", options->developer,
                  "developer mode: shaders from LUCENT_SHADER_DIR (default: the source "
                  "tree), reload button");
    cmd->callback([options, &exit_code] { exit_code = run_explore(*options); });
}

}  // namespace lucent::app
