#pragma once
// The single-image path shared by `lucent render`, batch rendering of stimulus sets and
// the explorer's "Save image": request -> scene -> frame plan -> GL -> float image.
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"
#include "renderer/gl/frame_executor.h"
#include "renderer/techniques/registry.h"

namespace lucent {

struct RenderRequest {
    std::string mesh = "torus_knot";  // built-in name (optionally ":faces") or a file
    std::string technique = default_technique_name();  // registry name
    std::vector<KnobAssignment> settings;  // applied over the defaults, in order
    int width = 512;
    int height = 512;
};

// Validates the technique and settings first (KnobError: one line naming the key and the
// accepted range), then loads the mesh (MeshError). Throws std::invalid_argument for a
// non-positive size.
Scene build_scene(const RenderRequest& request);

// A rendered image and what had to be repaired in it before anyone sees it.
struct RenderedImage {
    Image image;                        // finite everywhere
    std::size_t non_finite_pixels = 0;  // pixels that had a NaN or Inf channel (a bug)
};

// Plans `scene` under its technique, renders it with `executor` (current GL context) and
// replaces non-finite values (replace_non_finite), counting the pixels it repaired.
// Throws gl::GlError naming the pass when GL reports an error.
RenderedImage render_image_counted(gl::FrameExecutor& executor, const Scene& scene,
                                   PlanMode mode = PlanMode::pruned);
// render_image_counted() without the count, for callers that only display the image.
Image render_image(gl::FrameExecutor& executor, const Scene& scene,
                   PlanMode mode = PlanMode::pruned);

}  // namespace lucent
