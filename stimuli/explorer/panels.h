#pragma once
// The explorer's Dear ImGui panels: light, material, camera, technique and AO (their
// sliders generated from the technique registry's knob descriptions), view toggles,
// A/B comparison, actions, and the status bar. Panels edit the session directly and
// return the actions the user asked for; the Explorer carries them out.
#include <map>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/gl/frame_executor.h"
#include "stimuli/explorer/frame_stats.h"
#include "stimuli/explorer/session.h"

namespace lucent::explorer {

// Where a widget was drawn (window pixels), by knob name or button label: scripts aim
// their mouse events with it.
struct WidgetRect {
    float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// What the panels show but do not own.
struct PanelInfo {
    std::size_t faces = 0, vertices = 0;
    float near_plane = 0, far_plane = 0;
    FrameTimeSummary frame_times;
    const FramePlan* plan = nullptr;  // of the edited set's latest frame
    const gl::FrameTimings* timings = nullptr;
    bool baking = false;
    float bake_progress = 0;
    std::string bake_error;
    std::string buffer_message;
    std::string refinement;  // "refining: 64 of 256 samples" while a view converges
};

struct PanelRequests {
    bool save_image = false;
    bool add_to_stimulus_set = false;
    bool load_mesh = false;
    bool reload_shaders = false;
    bool rebake_ambient_occlusion = false;
};

// Draws every panel for this frame; fills `widgets` with the rects of what it drew.
PanelRequests draw_panels(ExplorerSession& session, const PanelInfo& info,
                          std::map<std::string, WidgetRect>& widgets);

}  // namespace lucent::explorer
