#include "stimuli/explorer/session.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "renderer/core/common_knobs.h"
#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"

namespace lucent::explorer {

ParameterSet::ParameterSet(std::string technique) { set_technique(technique); }

void ParameterSet::set_technique(const std::string& name) {
    const Technique& technique = find_technique(name);
    technique_ = std::string(technique.name());
    if (!values_by_technique_.count(technique_))
        values_by_technique_[technique_] = resolve_knob_values(knobs_for(technique), {});
}

const KnobValues& ParameterSet::values() const {
    return values_by_technique_.at(technique_);
}

void ParameterSet::set(const std::string& name, const KnobValue& value) {
    const std::vector<Knob> knobs = knobs_for(find_technique(technique_));
    const Knob* knob = find_knob(knobs, name);
    if (!knob)
        throw KnobError(name + ": not a parameter of technique '" + technique_ + "'");
    // Through text, as a config or --set would pass it: identical values, identical
    // pixels.
    values_by_technique_[technique_].set(
        name, parse_knob_value(*knob, format_knob_value(value)));
}

void ParameterSet::apply(const std::vector<KnobAssignment>& assignments) {
    const std::vector<Knob> knobs = knobs_for(find_technique(technique_));
    KnobValues updated = values();
    for (const auto& a : assignments) {
        const Knob* knob = find_knob(knobs, a.key);
        if (!knob)
            throw KnobError(a.key + ": not a parameter of technique '" + technique_ +
                            "'");
        updated.set(a.key, parse_knob_value(*knob, a.text));
    }
    values_by_technique_[technique_] = std::move(updated);
}

std::vector<KnobAssignment> ParameterSet::assignments() const {
    std::vector<KnobAssignment> out;
    for (const Knob& knob : knobs_for(find_technique(technique_)))
        out.push_back({knob.name, format_knob_value(values().get(knob.name))});
    return out;
}

const char* buffer_view_name(BufferView view) {
    switch (view) {
        case BufferView::shaded:
            return "shaded image";
        case BufferView::front_depth:
            return "front depth";
        case BufferView::second_layer:
            return "second layer depth";
        case BufferView::smoothed_thickness:
            return "smoothed second layer";
        case BufferView::ambient_occlusion:
            return "ambient occlusion";
    }
    return "shaded image";
}

glm::vec3 view_direction(const ExplorerSession& session) {
    const float yaw = glm::radians(session.yaw_degrees);
    const float pitch = glm::radians(session.pitch_degrees);
    return {std::sin(yaw) * std::cos(pitch), std::sin(pitch),
            std::cos(yaw) * std::cos(pitch)};
}

void orbit(ExplorerSession& session, float dx_pixels, float dy_pixels) {
    constexpr float kDegreesPerPixel = 0.4f;
    session.yaw_degrees =
        std::fmod(session.yaw_degrees - dx_pixels * kDegreesPerPixel, 360.f);
    session.pitch_degrees =
        std::clamp(session.pitch_degrees + dy_pixels * kDegreesPerPixel, -89.f, 89.f);
}

void drag_light(ExplorerSession& session, float dx_pixels, float dy_pixels) {
    constexpr float kRadiansPerPixel = 0.01f;
    ParameterSet& set = session.current();
    glm::vec3 direction = glm::normalize(glm::vec3(set.values().vec3("light_direction")));
    // Eye space: dragging right turns the light about Y towards +X, dragging down about
    // X.
    glm::mat4 turn =
        glm::rotate(glm::mat4(1.f), dx_pixels * kRadiansPerPixel, {0.f, 1.f, 0.f});
    turn = glm::rotate(turn, dy_pixels * kRadiansPerPixel, {1.f, 0.f, 0.f});
    direction = glm::normalize(glm::vec3(turn * glm::vec4(direction, 0.f)));
    set.set("light_direction", glm::dvec3(direction));
}

void zoom(ExplorerSession& session, float notches) {
    ParameterSet& set = session.current();
    const auto& knobs = scene_knobs();
    const Knob* fov = find_knob(knobs, "fov_y");
    const double value = set.values().scalar("fov_y") * std::pow(0.95, notches);
    set.set("fov_y", std::clamp(value, fov->min, fov->max));
}

RenderRequest render_request(const ExplorerSession& session, int side, int width,
                             int height) {
    RenderRequest request;
    request.mesh = session.mesh;
    request.technique = session.sets[side].technique();
    request.settings = session.sets[side].assignments();
    request.width = width;
    request.height = height;
    return request;
}

KnobGroup knob_group(const Knob& knob) {
    if (knob.name == "fov_y") return KnobGroup::camera;
    if (find_knob(scene_knobs(), knob.name)) return KnobGroup::light;
    for (const Knob& material :
         {albedo_knob(), ambient_knob(), specular_knob(), shininess_knob()})
        if (material.name == knob.name) return KnobGroup::material;
    if (knob.name == ao_rays_knob().name) return KnobGroup::ambient_occlusion;
    // A knob that names its panel (an input and its settings: htsm's density volume).
    if (!knob.panel.empty()) return KnobGroup::own_panel;
    return KnobGroup::technique;
}

}  // namespace lucent::explorer

namespace lucent::explorer {

ExplorerSession session_from_config(const std::string& config_path) {
    const StimulusSet set = load_stimulus_set(config_path, default_set_catalog());
    const Stimulus& first = set.stimuli.front();  // the loader rejects empty sets
    ExplorerSession session;
    session.mesh = first.mesh;
    for (ParameterSet& parameters : session.sets) {
        parameters.set_technique(first.technique);
        for (const auto& [name, value] : first.values.all()) parameters.set(name, value);
    }
    session.stimulus_config = config_path;
    session.stimulus_id = first.id + "_explored";
    return session;
}

}  // namespace lucent::explorer
