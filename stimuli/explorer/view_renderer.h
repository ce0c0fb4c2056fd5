#pragma once
// Renders what an explorer session shows: the edited parameter set, or sets A and B side
// by side, each through the same scene -> frame plan -> FrameExecutor path as
// `lucent render`, or a debug view of an intermediate buffer. Results are uploaded to
// 8-bit sRGB textures for display. Needs the window's GL context to be current.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/progressive.h"
#include "renderer/core/scene.h"
#include "renderer/gl/frame_executor.h"
#include "renderer/gl/objects.h"
#include "stimuli/explorer/background_bakes.h"
#include "stimuli/explorer/session.h"

namespace lucent::explorer {

// One parameter set's latest frame.
struct RenderedSide {
    bool valid = false;  // false until the first frame (e.g. while the AO bakes)
    Scene scene;         // its camera places overlays
    FramePlan plan;
    Image image;               // linear float, as `lucent render` writes it
    gl::FrameTimings timings;  // per pass, when the session asks for them
    gl::Texture texture;  // what is displayed (shaded image or buffer view), sRGB 8-bit
    int texture_width = 0, texture_height = 0;
    BufferView shown_view = BufferView::shaded;  // what `texture` shows
    // Read-backs of the output so far: a frame in which no pass re-ran reads none (it
    // keeps showing `texture`).
    std::size_t read_backs = 0;
    // A technique refined over frames (Technique::progressive_refinement()): the mean
    // shown so far; `image` is then that mean.
    std::optional<ProgressiveAccumulator> refinement;
    // "refining: 64 of 256 samples", or "" when the image is complete.
    std::string refinement_status() const;
};

class ViewRenderer {
public:
    ViewRenderer() = default;
    // Renders the shown sets at width x height pixels in all (side by side: half each).
    // A set whose bakes (the AO) are still running keeps its previous frame; with
    // session.ambient_occlusion off, bakes that have a stand-in show it instead.
    void render(const ExplorerSession& session, const std::shared_ptr<const Mesh>& mesh,
                int width, int height);
    // The sets shown, in screen order (one, or A then B).
    const std::vector<int>& shown() const { return shown_; }
    const RenderedSide& side(int index) const { return sides_[index]; }
    BackgroundBakes& bakes() { return bakes_; }
    // Why the buffer view shows nothing (the buffer is not in the plan), else "".
    const std::string& buffer_message() const { return buffer_message_; }
    // Drops every executor: shaders compile again (read from LUCENT_SHADER_DIR when it
    // is set) and baked data is uploaded again from the bakes.
    void drop_executors() { executors_.clear(); }

private:
    // `bakes` false: the executor uploads the stand-ins of bakes that have one.
    gl::FrameExecutor& executor(const std::string& key, bool bakes);
    // Executes `scene`; false when a bake it uploads is still running.
    bool execute(gl::FrameExecutor& executor, const Scene& scene, const FramePlan& plan,
                 bool bakes, bool time_passes);
    void render_side(const ExplorerSession& session,
                     const std::shared_ptr<const Mesh>& mesh, int index, int width,
                     int height);

    std::map<std::string, std::unique_ptr<gl::FrameExecutor>> executors_;
    BackgroundBakes bakes_;
    RenderedSide sides_[2];
    std::vector<int> shown_;
    std::string buffer_message_;
};

// Linear float RGBA -> the 8-bit RGBA a PNG of it stores (display_code), alpha opaque.
std::vector<std::uint8_t> encode_for_display(const Image& image);
// A single-channel depth buffer as grey: near bright, far dark, background (1) black.
std::vector<std::uint8_t> depth_for_display(const std::vector<float>& depth);

}  // namespace lucent::explorer
