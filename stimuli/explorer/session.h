#pragma once
// The explorer's persistent state (Polyscope's persistent values, kept in one session
// object instead of globals): what is shown, two parameter sets for A/B comparison, the
// view, and the action fields. GL-free, so tests and the CLI can build one without a
// window. Parameters are knob values of the technique registry; nothing here lists the
// parameters of a particular technique.
#include <glm/glm.hpp>
#include <map>
#include <string>
#include <vector>

#include "renderer/core/knobs.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"

namespace lucent::explorer {

// The knob values of one parameter set. Values are kept per technique, so switching
// technique and back restores what was set before.
class ParameterSet {
public:
    ParameterSet() : ParameterSet(default_technique_name()) {}
    explicit ParameterSet(std::string technique);
    const std::string& technique() const { return technique_; }
    // Switches technique (throws KnobError for an unknown name).
    void set_technique(const std::string& name);
    const KnobValues& values() const;
    // Sets one value after validating it against the technique's knob and rounding it
    // through its text form, so the value equals what `--set` or a config would give.
    // Throws KnobError (unknown knob, out of range).
    void set(const std::string& knob, const KnobValue& value);
    // Applies `key=value` texts over the current values (KnobError on a bad one).
    void apply(const std::vector<KnobAssignment>& assignments);
    // Every knob as `key=value`, in knob order: what `lucent render --set` takes.
    std::vector<KnobAssignment> assignments() const;

private:
    std::string technique_;
    std::map<std::string, KnobValues> values_by_technique_;
};

// Debug views of intermediate results instead of the shaded image.
enum class BufferView {
    shaded,
    front_depth,
    second_layer,
    smoothed_thickness,
    ambient_occlusion
};
const char* buffer_view_name(BufferView view);

struct ExplorerSession {
    std::string mesh = "torus_knot:60k";  // built-in spec or file path
    ParameterSet sets[2];                 // A and B
    int edited = 0;                       // the set the panels edit; A/B flip swaps it
    bool side_by_side = false;            // show A and B beside each other

    // View (explorer only: a stimulus entry stores knobs, so orbiting is not stored).
    float yaw_degrees = 0.f;    // orbit about the object's Y axis
    float pitch_degrees = 0.f;  // orbit up/down, kept inside (-89, 89)
    bool auto_rotate = false;
    float rotate_degrees_per_second = 30.f;
    bool random_light_motion = false;
    bool ambient_occlusion = true;  // off: preview with AO = 1 (not a knob; not saved)
    bool show_axes = false;
    bool show_bounds = false;
    bool show_pass_times = false;
    BufferView buffer_view = BufferView::shaded;
    bool developer_mode = false;  // shader reload from LUCENT_SHADER_DIR

    // Action fields.
    std::string mesh_path_field;
    std::string stimulus_config = "explore_stimuli.toml";
    std::string stimulus_id = "explore";
    std::string save_image_path = "explore.png";
    std::string message;  // last action's result, shown in the status bar

    ParameterSet& current() { return sets[edited]; }
    const ParameterSet& current() const { return sets[edited]; }
    // Whether the camera looks along the default +Z direction (as `lucent render` does).
    bool default_view() const { return yaw_degrees == 0.f && pitch_degrees == 0.f; }
};

// Direction from the object's centre towards the eye for the session's orbit.
glm::vec3 view_direction(const ExplorerSession& session);
// Orbits by a mouse drag of (dx, dy) pixels (0.4 degrees per pixel).
void orbit(ExplorerSession& session, float dx_pixels, float dy_pixels);
// Turns the light direction knob of the edited set by a drag of (dx, dy) pixels.
void drag_light(ExplorerSession& session, float dx_pixels, float dy_pixels);
// Zooms by mouse-wheel notches: scales the fov_y knob (clamped to its range).
void zoom(ExplorerSession& session, float notches);

// What `lucent render` needs to make the same image as set `side` at width x height.
RenderRequest render_request(const ExplorerSession& session, int side, int width,
                             int height);

// The panel a knob belongs to: scene knobs by their group, shared material knobs,
// ao_rays under AO, and everything else under the technique.
// `own_panel`: a knob that names its panel (Knob::panel, e.g. a volume and its settings).
enum class KnobGroup { light, camera, material, ambient_occlusion, own_panel, technique };
KnobGroup knob_group(const Knob& knob);

}  // namespace lucent::explorer

namespace lucent::explorer {

// A session starting from the first stimulus of a stimulus-set config (its mesh,
// technique and parameters in both sets), with "Add to stimulus set" aimed at that file.
// Throws StimulusSetError naming the file, line and key.
ExplorerSession session_from_config(const std::string& config_path);

}  // namespace lucent::explorer
