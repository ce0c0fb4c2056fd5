#pragma once
// `lucent explore`: a window where a stimulus author finds parameters by eye (thesis
// tool, seeds.md section A "UI"). One Explorer owns the window, the input router, the
// view renderer and the session; step() runs one frame. Actions ("Save image", "Add to
// stimulus set", loading a mesh, reloading shaders) are public so the CLI and tests call
// the same functions the buttons do.
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "renderer/core/mesh.h"
#include "stimuli/explorer/frame_stats.h"
#include "stimuli/explorer/input.h"
#include "stimuli/explorer/panels.h"
#include "stimuli/explorer/session.h"
#include "stimuli/explorer/view_renderer.h"

namespace lucent::ui {
class ImGuiWindow;
}

namespace lucent::explorer {

struct ExplorerOptions {
    int width = 1280;  // window size; the view renders at its framebuffer size
    int height = 720;
    bool visible = true;
    float font_pixels = 15.f;
};

class Explorer {
public:
    // Loads the session's mesh (MeshError) and opens the window (gl::ContextError).
    Explorer(ExplorerSession session, const ExplorerOptions& options);
    ~Explorer();
    Explorer(const Explorer&) = delete;
    Explorer& operator=(const Explorer&) = delete;

    void step();  // one frame: input, panels, actions, render, present
    bool should_close() const;

    ExplorerSession& session() { return session_; }
    InputRouter& input() { return *input_; }
    const Mesh& mesh() const { return *mesh_; }
    // The latest frame of the edited set (the left one when side by side shows both).
    const RenderedSide& shown() const;
    const RenderedSide& side(int index) const;  // set A (0) or B (1), as last rendered
    bool ambient_occlusion_pending() const;
    FrameTimeSummary frame_times() const { return stats_.summary(); }  // the last second
    double last_frame_ms() const { return last_frame_ms_; }
    // Where the last frame drew a widget (knob name or button label).
    std::optional<WidgetRect> widget(const std::string& id) const;
    // The size one set renders at: the framebuffer, or half its width side by side.
    void view_size(int& width, int& height) const;

    // "Save image": the edited set at the view size through lucent::build_scene,
    // render_image_counted and write_image, as `lucent render` does. Returns the number
    // of pixels that had NaN or Inf values (replaced). Throws on failure.
    std::size_t save_image(const std::filesystem::path& path);
    // "Add to stimulus set": returns the id written (explorer/stimulus_entry.h).
    std::string add_to_stimulus_set(const std::filesystem::path& config,
                                    const std::string& id);
    void load_mesh(const std::string& spec);  // MeshError: the old mesh stays
    void reload_shaders();
    // Writes the window's pixels (panels included) as PNG at the end of the next step().
    void request_screenshot(const std::filesystem::path& path) { screenshot_ = path; }

private:
    void animate(float seconds);
    void handle(const PanelRequests& requests);
    void draw_view();
    PanelInfo panel_info() const;

    ExplorerSession session_;
    std::shared_ptr<const Mesh> mesh_;
    glm::vec3 mesh_min_{0.f}, mesh_max_{0.f};
    // Declared in this order so GL objects go before the window's context.
    std::unique_ptr<ui::ImGuiWindow> window_;
    std::unique_ptr<InputRouter> input_;
    std::unique_ptr<ViewRenderer> view_;
    FrameStats stats_;
    std::map<std::string, WidgetRect> widgets_;
    std::filesystem::path screenshot_;
    double last_frame_end_ = -1.0;
    double last_frame_ms_ = 0.0;
    std::mt19937 light_motion_{20110601};
    glm::vec2 light_velocity_{0.f};
};

}  // namespace lucent::explorer
