#include "stimuli/explorer/view_renderer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "renderer/core/display_transform.h"
#include "renderer/core/technique.h"
#include "renderer/gl/upload.h"
#include "renderer/techniques/registry.h"

namespace lucent::explorer {
namespace {

// The frame resources each depth view shows (names from the empirical technique's plan).
const char* buffer_resource(BufferView view) {
    switch (view) {
        case BufferView::front_depth:
            return "front_depth";
        case BufferView::second_layer:
            return "second_depth";
        case BufferView::smoothed_thickness:
            return "smoothed_depth";
        default:
            return "";
    }
}

// The AO view: the empirical technique lit by ambient light only with unit reflectance,
// so Eq. 3.6 reduces to a * 1 * 1 * 1 = a, through the same passes as any frame.
Scene ambient_occlusion_scene(const Scene& shown, const std::shared_ptr<const Mesh>& mesh,
                              glm::vec3 view_direction) {
    const Technique& empirical = find_technique("empirical");
    KnobValues values = resolve_knob_values(
        knobs_for(empirical), std::vector<KnobAssignment>{{"light_ambient", "1"},
                                                          {"light_diffuse", "0"},
                                                          {"light_specular", "0"},
                                                          {"ambient", "1"},
                                                          {"albedo", "1"},
                                                          {"backlight", "0"}});
    if (shown.values.contains("ao_rays"))
        values.set("ao_rays", shown.values.get("ao_rays"));
    values.set("fov_y", shown.values.get("fov_y"));
    return make_scene(mesh, empirical, std::move(values), shown.width, shown.height,
                      view_direction);
}

void upload(RenderedSide& side, const std::vector<std::uint8_t>& rgba, int width,
            int height) {
    if (side.texture_width != width || side.texture_height != height ||
        !side.texture.id()) {
        side.texture = gl::make_texture_2d(GL_RGBA8, width, height);
        side.texture_width = width;
        side.texture_height = height;
    }
    gl::upload_texture_rgba8(side.texture, width, height, rgba);
}

}  // namespace

std::vector<std::uint8_t> encode_for_display(const Image& image) {
    std::vector<std::uint8_t> out(image.rgba.size());
    for (std::size_t i = 0; i < image.rgba.size(); ++i)
        out[i] = (i % 4 == 3) ? 255 : display_code(image.rgba[i]);
    return out;
}

std::vector<std::uint8_t> depth_for_display(const std::vector<float>& depth) {
    float near = 1.f, far = 0.f;
    for (float d : depth)
        if (d < 1.f) near = std::min(near, d), far = std::max(far, d);
    const float span = far > near ? far - near : 1.f;
    std::vector<std::uint8_t> out(depth.size() * 4, 255);
    for (std::size_t i = 0; i < depth.size(); ++i) {
        const float d = depth[i];
        const float grey = d < 1.f ? 1.f - 0.85f * (d - near) / span : 0.f;
        const auto g =
            static_cast<std::uint8_t>(std::lround(std::clamp(grey, 0.f, 1.f) * 255.f));
        out[i * 4] = out[i * 4 + 1] = out[i * 4 + 2] = g;
    }
    return out;
}

namespace {

// Whether the explorer bakes `pass` (in the background) rather than showing a stand-in.
bool baked(const Pass& pass, bool bakes) {
    return is_bake(pass) && (bakes || !pass.data.stand_in);
}

}  // namespace

gl::FrameExecutor& ViewRenderer::executor(const std::string& key, bool bakes) {
    const std::string full = key + (bakes ? "" : "/stand-ins");
    auto& slot = executors_[full];
    if (!slot) {
        slot = std::make_unique<gl::FrameExecutor>();
        // A frame re-runs only the passes whose inputs a slider (or the view) changed.
        slot->set_reuse_unchanged_passes(true);
        // Bakes come from the background (execute() runs a plan only once they are
        // done), or are their stand-ins; other uploads are produced in line.
        slot->set_upload_producer([this, bakes](const Pass& pass) {
            if (!is_bake(pass)) return produce_upload(pass);
            if (!baked(pass, bakes)) return pass.data.stand_in();
            if (const TextureData* data = bakes_.find(pass.data.content_hash))
                return *data;
            throw std::runtime_error("pass '" + pass.name +
                                     "' uploaded before its bake finished");
        });
    }
    return *slot;
}

bool ViewRenderer::execute(gl::FrameExecutor& executor, const Scene& scene,
                           const FramePlan& plan, bool bakes, bool time_passes) {
    for (const Pass& pass : plan.passes)
        if (baked(pass, bakes) && !bakes_.find_or_start(pass)) return false;
    executor.execute(scene, plan, time_passes);
    return true;
}

void ViewRenderer::render_side(const ExplorerSession& session,
                               const std::shared_ptr<const Mesh>& mesh, int index,
                               int width, int height) {
    RenderedSide& side = sides_[index];
    const ParameterSet& set = session.sets[index];
    const Technique& technique = find_technique(set.technique());
    KnobValues values = set.values();
    const ProgressiveRefinement refinement = technique.progressive_refinement();
    const bool refine = refinement.enabled() && session.buffer_view == BufferView::shaded;
    if (!refine) side.refinement.reset();
    if (refine) {
        if (!side.refinement || side.scene.technique != technique.name())
            side.refinement.emplace(refinement);
        const glm::vec3 direction = view_direction(session);
        char view[160];
        std::snprintf(view, sizeof view, "%s %dx%d %.9g,%.9g,%.9g ao=%d",
                      mesh->content_hash.c_str(), width, height, direction.x, direction.y,
                      direction.z, session.ambient_occlusion ? 1 : 0);
        const auto knobs = knobs_for(technique);
        const auto seed = std::find_if(knobs.begin(), knobs.end(), [&](const Knob& k) {
            return k.name == refinement.seed_knob;
        });
        auto frame_values = side.refinement->next(
            values, view, seed == knobs.end() ? 0 : static_cast<int>(seed->max));
        if (!frame_values && side.valid) return;  // converged: nothing runs
        if (frame_values) values = std::move(*frame_values);
    }
    Scene scene = make_scene(mesh, technique, std::move(values), width, height,
                             view_direction(session));
    // A depth view keeps the pass that makes its layer even where the image does not
    // need it (a closed mesh's smoothing happens inside `shade`).
    const std::string viewed = buffer_resource(session.buffer_view);
    FramePlan plan = make_frame_plan(
        scene, technique, PlanMode::pruned,
        viewed.empty() ? std::vector<std::string>{} : std::vector<std::string>{viewed});
    // A frame that waits for a bake keeps showing the last complete one.
    const Scene previous = std::move(side.scene);
    side.scene = scene;
    const std::string key = "side" + std::to_string(index);
    // The AO checkbox: off previews the stand-ins of bakes (the AO's: every vertex open).
    gl::FrameExecutor& shading = executor(key, session.ambient_occlusion);
    if (!execute(shading, scene, plan, session.ambient_occlusion,
                 session.show_pass_times)) {
        if (side.valid) side.scene = previous;  // keep showing the last complete frame
        return;
    }
    // Nothing re-ran (pass reuse): the output is the one already read and shown, so the
    // read-back, encoding and upload (most of an idle frame at 1280x720) are skipped.
    const auto& passes = shading.last_timings().passes;
    const bool unchanged =
        side.valid && !side.refinement && session.buffer_view == BufferView::shaded &&
        side.shown_view == BufferView::shaded && side.texture_width == width &&
        side.texture_height == height && side.plan.output == plan.output &&
        !passes.empty() &&
        std::all_of(passes.begin(), passes.end(), [](const auto& p) { return p.cached; });
    if (unchanged) {
        side.timings = shading.last_timings();
        side.plan = std::move(plan);
        return;
    }
    side.image = shading.read_output(plan);
    ++side.read_backs;
    replace_non_finite(side.image);
    if (side.refinement && side.refinement->target() > 0 &&
        !side.refinement->converged()) {
        side.refinement->add(side.image);
        side.image = side.refinement->mean();
    }
    side.timings = shading.last_timings();
    side.plan = std::move(plan);
    side.valid = true;
    side.shown_view = session.buffer_view;

    switch (session.buffer_view) {
        case BufferView::shaded:
            upload(side, encode_for_display(side.image), width, height);
            break;
        case BufferView::ambient_occlusion: {
            const Scene ao_scene =
                ambient_occlusion_scene(scene, mesh, view_direction(session));
            const FramePlan ao_plan =
                make_frame_plan(ao_scene, find_technique("empirical"));
            gl::FrameExecutor& ao = executor(key + "/ao-view", true);
            if (execute(ao, ao_scene, ao_plan, true, false)) {
                Image image = ao.read_output(ao_plan);
                replace_non_finite(image);
                upload(side, encode_for_display(image), width, height);
            }
            break;
        }
        default: {
            const std::string resource = buffer_resource(session.buffer_view);
            const auto allocated = shading.allocated_resources();
            if (std::find(allocated.begin(), allocated.end(), resource) ==
                allocated.end()) {
                buffer_message_ = std::string(buffer_view_name(session.buffer_view)) +
                                  " is not in the current frame plan";
                upload(side, encode_for_display(side.image), width, height);
            } else {
                upload(side, depth_for_display(shading.read_channel(resource)), width,
                       height);
            }
        }
    }
}

std::string RenderedSide::refinement_status() const {
    if (!refinement || refinement->converged() || refinement->frames() == 0) return "";
    return "refining: " + std::to_string(refinement->samples()) + " of " +
           std::to_string(refinement->target()) + " samples";
}

void ViewRenderer::render(const ExplorerSession& session,
                          const std::shared_ptr<const Mesh>& mesh, int width,
                          int height) {
    buffer_message_.clear();
    shown_ =
        session.side_by_side ? std::vector<int>{0, 1} : std::vector<int>{session.edited};
    const int each = session.side_by_side ? std::max(1, width / 2) : width;
    for (int index : shown_) render_side(session, mesh, index, each, std::max(1, height));
}

}  // namespace lucent::explorer
