#include "stimuli/explorer/panels.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>

#include "renderer/techniques/registry.h"
#include "stimuli/explorer/pass_times.h"

namespace lucent::explorer {
namespace {

constexpr float kPanelWidth = 440.f;

// Records the last item's rect; for labelled widgets only the frame (the label is not
// part of the slider), so a click at a fraction of the width means that fraction.
void remember(const std::string& id, std::map<std::string, WidgetRect>& widgets,
              bool labelled = false) {
    if (!ImGui::IsItemVisible()) return;
    const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
    widgets[id] = {a.x, a.y, labelled ? std::min(b.x, a.x + ImGui::CalcItemWidth()) : b.x,
                   b.y};
}

bool button(const char* label, std::map<std::string, WidgetRect>& widgets) {
    const bool pressed = ImGui::Button(label);
    remember(label, widgets);
    return pressed;
}

bool wide_range(const Knob& knob) { return knob.max - knob.min > 100.0; }

// One widget for `knob`, by kind and documented range; the value goes through
// ParameterSet::set, which validates it exactly as a config would.
void knob_widget(ParameterSet& set, const Knob& knob, ExplorerSession& session,
                 std::map<std::string, WidgetRect>& widgets) {
    KnobValue value = set.values().get(knob.name);
    bool changed = false;
    const char* label = knob.name.c_str();
    const float lo = static_cast<float>(knob.min), hi = static_cast<float>(knob.max);
    ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp;
    if (wide_range(knob)) flags |= ImGuiSliderFlags_Logarithmic;
    switch (knob.kind) {
        case KnobKind::scalar: {
            float v = static_cast<float>(std::get<double>(value));
            changed = ImGui::SliderFloat(label, &v, lo, hi, "%.3f", flags);
            value = static_cast<double>(v);
            break;
        }
        case KnobKind::integer: {
            int v = std::get<int>(value);
            changed = ImGui::SliderInt(label, &v, static_cast<int>(knob.min),
                                       static_cast<int>(knob.max), "%d", flags);
            value = v;
            break;
        }
        case KnobKind::choice: {
            const std::string& current = std::get<std::string>(value);
            if (ImGui::BeginCombo(label, current.c_str())) {
                for (const auto& choice : knob.choices)
                    if (ImGui::Selectable(choice.c_str(), choice == current)) {
                        value = choice;
                        changed = true;
                    }
                ImGui::EndCombo();
            }
            break;
        }
        case KnobKind::text: {
            // Applied on Enter, so a half-typed spec is never rendered.
            char buffer[512];
            std::snprintf(buffer, sizeof buffer, "%s",
                          std::get<std::string>(value).c_str());
            if (ImGui::InputText(label, buffer, sizeof buffer,
                                 ImGuiInputTextFlags_EnterReturnsTrue)) {
                value = std::string(buffer);
                changed = true;
            }
            break;
        }
        case KnobKind::rgb:
        case KnobKind::vec3: {
            const glm::dvec3 d = std::get<glm::dvec3>(value);
            float v[3] = {float(d.x), float(d.y), float(d.z)};
            if (knob.kind == KnobKind::rgb && knob.max <= 1.0)
                changed = ImGui::ColorEdit3(label, v, ImGuiColorEditFlags_Float);
            else
                changed = ImGui::DragFloat3(label, v, 0.01f, lo, hi, "%.3f",
                                            ImGuiSliderFlags_AlwaysClamp);
            value = glm::dvec3(v[0], v[1], v[2]);
            break;
        }
    }
    remember(knob.name, widgets, true);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("%s\naccepted: %s", knob.description.c_str(),
                          accepted_range(knob).c_str());
    if (!changed) return;
    try {
        set.set(knob.name, value);
    } catch (const KnobError& e) {
        session.message = e.what();  // e.g. a zero light direction; the old value stays
    }
}

void group_widgets(ExplorerSession& session, KnobGroup group,
                   std::map<std::string, WidgetRect>& widgets) {
    ParameterSet& set = session.current();
    for (const Knob& knob : knobs_for(find_technique(set.technique())))
        if (knob_group(knob) == group) knob_widget(set, knob, session, widgets);
}

// The panels knobs name for themselves (Knob::panel), in knob order: "Density" holds
// htsm's volume, its resolution, contrast and scale.
std::vector<std::string> own_panels(ExplorerSession& session) {
    std::vector<std::string> panels;
    for (const Knob& knob : knobs_for(find_technique(session.current().technique())))
        if (!knob.panel.empty() &&
            std::find(panels.begin(), panels.end(), knob.panel) == panels.end())
            panels.push_back(knob.panel);
    return panels;
}

// One such panel: a button per suggested value (a volume's generators), the knobs'
// widgets, then a line on each input (its size and hash: what is rendered).
void own_panel(ExplorerSession& session, const std::string& panel,
               std::map<std::string, WidgetRect>& widgets) {
    ParameterSet& set = session.current();
    const std::vector<Knob> knobs = knobs_for(find_technique(set.technique()));
    for (const Knob& knob : knobs) {
        if (knob.panel != panel || knob.suggestions.empty()) continue;
        for (const std::string& value : knob.suggestions) {
            if (button(value.c_str(), widgets)) {
                try {
                    set.set(knob.name, value);
                } catch (const KnobError& e) {
                    session.message = e.what();
                }
            }
            ImGui::SameLine();
        }
        ImGui::NewLine();
    }
    for (const Knob& knob : knobs)
        if (knob.panel == panel) knob_widget(set, knob, session, widgets);
    for (const Knob& knob : knobs) {
        if (knob.panel != panel || !knob.describe_input) continue;
        try {
            ImGui::TextDisabled("%s", knob.describe_input(set.values()).c_str());
        } catch (const KnobError& e) {
            ImGui::TextDisabled("%s", e.what());
        }
    }
}

void text_field(const char* label, std::string& text) {
    char buffer[1024];
    std::snprintf(buffer, sizeof buffer, "%s", text.c_str());
    if (ImGui::InputText(label, buffer, sizeof buffer)) text = buffer;
}

void mesh_and_technique(ExplorerSession& session, PanelRequests& requests,
                        std::map<std::string, WidgetRect>& widgets) {
    ImGui::Text("mesh: %s", session.mesh.c_str());
    text_field("##mesh path", session.mesh_path_field);
    ImGui::SameLine();
    requests.load_mesh = button("Load mesh", widgets);
    ParameterSet& set = session.current();
    if (ImGui::BeginCombo("technique", set.technique().c_str())) {
        for (const Technique* technique : all_techniques()) {
            const std::string name(technique->name());
            if (ImGui::Selectable(name.c_str(), name == set.technique()))
                set.set_technique(name);
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("%s", std::string(technique->description()).c_str());
        }
        ImGui::EndCombo();
    }
    remember("technique", widgets);
    // A/B: two parameter sets, flipped with the button or the space bar.
    ImGui::RadioButton("edit A", &session.edited, 0);
    ImGui::SameLine();
    ImGui::RadioButton("edit B", &session.edited, 1);
    ImGui::SameLine();
    if (button("Flip A/B", widgets)) session.edited = 1 - session.edited;
    ImGui::SameLine();
    if (button("Copy to other", widgets))
        session.sets[1 - session.edited] = session.current();
    ImGui::Checkbox("side by side", &session.side_by_side);
}

void camera_panel(ExplorerSession& session, const PanelInfo& info,
                  std::map<std::string, WidgetRect>& widgets) {
    group_widgets(session, KnobGroup::camera, widgets);
    ImGui::Text("near %.4g  far %.4g (hug the bounding sphere)", info.near_plane,
                info.far_plane);
    ImGui::SliderFloat("yaw", &session.yaw_degrees, -180.f, 180.f, "%.1f deg");
    ImGui::SliderFloat("pitch", &session.pitch_degrees, -89.f, 89.f, "%.1f deg");
    ImGui::Checkbox("auto-rotate about Y", &session.auto_rotate);
    ImGui::SliderFloat("speed", &session.rotate_degrees_per_second, 1.f, 180.f,
                       "%.0f deg/s");
    if (button("Reset view", widgets)) session.yaw_degrees = session.pitch_degrees = 0.f;
    ImGui::TextDisabled(
        "left-drag orbits, wheel zooms (fov_y); orbit is not saved in configs");
}

void ambient_occlusion_panel(ExplorerSession& session, const PanelInfo& info,
                             PanelRequests& requests,
                             std::map<std::string, WidgetRect>& widgets) {
    ImGui::Checkbox("ambient occlusion (off: preview only)", &session.ambient_occlusion);
    group_widgets(session, KnobGroup::ambient_occlusion, widgets);
    requests.rebake_ambient_occlusion = button("Re-bake", widgets);
    if (info.baking)
        ImGui::ProgressBar(info.bake_progress, ImVec2(-1.f, 0.f),
                           "baking ambient occlusion");
    if (!info.bake_error.empty()) ImGui::TextWrapped("%s", info.bake_error.c_str());
}

void view_panel(ExplorerSession& session, const PanelInfo& info, PanelRequests& requests,
                std::map<std::string, WidgetRect>& widgets) {
    ImGui::Checkbox("axes", &session.show_axes);
    ImGui::SameLine();
    ImGui::Checkbox("bounding box", &session.show_bounds);
    ImGui::SameLine();
    ImGui::Checkbox("pass times", &session.show_pass_times);
    if (ImGui::BeginCombo("buffer", buffer_view_name(session.buffer_view))) {
        for (BufferView view :
             {BufferView::shaded, BufferView::front_depth, BufferView::second_layer,
              BufferView::smoothed_thickness, BufferView::ambient_occlusion})
            if (ImGui::Selectable(buffer_view_name(view), view == session.buffer_view))
                session.buffer_view = view;
        ImGui::EndCombo();
    }
    if (!info.buffer_message.empty())
        ImGui::TextWrapped("%s", info.buffer_message.c_str());
    ImGui::Checkbox("developer mode", &session.developer_mode);
    if (session.developer_mode) {
        ImGui::SameLine();
        requests.reload_shaders = button("Reload shaders", widgets);
    }
}

void actions_panel(ExplorerSession& session, PanelRequests& requests,
                   std::map<std::string, WidgetRect>& widgets) {
    text_field("image file", session.save_image_path);
    requests.save_image = button("Save image", widgets);
    text_field("config", session.stimulus_config);
    text_field("stimulus id", session.stimulus_id);
    requests.add_to_stimulus_set = button("Add to stimulus set", widgets);
}

void status_bar(ExplorerSession& session, const PanelInfo& info) {
    const ImGuiViewport* viewport = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(ImVec2(viewport->Pos.x, viewport->Pos.y + viewport->Size.y),
                            ImGuiCond_Always, ImVec2(0.f, 1.f));
    ImGui::SetNextWindowSize(ImVec2(viewport->Size.x, 0.f));
    ImGui::SetNextWindowBgAlpha(0.75f);
    ImGui::Begin("status", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                     ImGuiWindowFlags_AlwaysAutoResize |
                     ImGuiWindowFlags_NoSavedSettings);
    const FrameTimeSummary& t = info.frame_times;
    std::string passes;
    if (info.plan)
        for (const Pass& pass : info.plan->passes)
            passes += (passes.empty() ? "" : ", ") + pass.name;
    ImGui::Text(
        "frame ms min %.1f  mean %.1f  max %.1f (last second) | %zu faces, %zu vertices",
        t.min_ms, t.mean_ms, t.max_ms, info.faces, info.vertices);
    ImGui::TextWrapped("plan (%s): %s", session.current().technique().c_str(),
                       passes.c_str());
    if (session.show_pass_times && info.timings)
        ImGui::TextWrapped("%s", pass_times_text(*info.timings).c_str());
    if (!info.refinement.empty()) ImGui::TextUnformatted(info.refinement.c_str());
    if (!session.message.empty()) ImGui::TextUnformatted(session.message.c_str());
    ImGui::End();
}

}  // namespace

PanelRequests draw_panels(ExplorerSession& session, const PanelInfo& info,
                          std::map<std::string, WidgetRect>& widgets) {
    widgets.clear();
    PanelRequests requests;
    const ImGuiViewport* viewport = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(viewport->Pos, ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, viewport->Size.y - 48.f),
                             ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.8f);
    ImGui::Begin("Lucent explorer", nullptr, ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushItemWidth(-170.f);
    mesh_and_technique(session, requests, widgets);
    if (ImGui::CollapsingHeader("Save", ImGuiTreeNodeFlags_DefaultOpen))
        actions_panel(session, requests, widgets);
    if (ImGui::CollapsingHeader("Technique", ImGuiTreeNodeFlags_DefaultOpen))
        group_widgets(session, KnobGroup::technique, widgets);
    for (const std::string& panel : own_panels(session))
        if (ImGui::CollapsingHeader(panel.c_str(), ImGuiTreeNodeFlags_DefaultOpen))
            own_panel(session, panel, widgets);
    if (ImGui::CollapsingHeader("Material", ImGuiTreeNodeFlags_DefaultOpen))
        group_widgets(session, KnobGroup::material, widgets);
    if (ImGui::CollapsingHeader("Light", ImGuiTreeNodeFlags_DefaultOpen)) {
        group_widgets(session, KnobGroup::light, widgets);
        ImGui::Checkbox("random light motion", &session.random_light_motion);
        ImGui::TextDisabled("right-drag on the view moves the light");
    }
    if (ImGui::CollapsingHeader("Camera")) camera_panel(session, info, widgets);
    if (ImGui::CollapsingHeader("Ambient occlusion"))
        ambient_occlusion_panel(session, info, requests, widgets);
    if (ImGui::CollapsingHeader("View")) view_panel(session, info, requests, widgets);
    ImGui::PopItemWidth();
    ImGui::End();
    status_bar(session, info);
    return requests;
}

}  // namespace lucent::explorer
