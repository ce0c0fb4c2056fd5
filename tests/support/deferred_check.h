#pragma once
// The check every deferred lighting pass (techniques/deferred_surface.h) passes: the
// technique's own plan (deferred) and the same scene planned forward render the same
// floats, bit for bit, and the image is lit.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>

#include "renderer/core/technique.h"
#include "renderer/gl/frame_executor.h"
#include "renderer/techniques/registry.h"
#include "tests/support/scene_for_test.h"

namespace lucent::test {

// `plan_forward` adds the technique's passes with SurfaceShading::forward;
// `surface_pass` is the deferred plan's pass that stores the surface, and the deferred
// image's brightest channel must exceed `min_peak`.
inline void expect_deferred_equals_forward(
    gl::FrameExecutor& executor, const Scene& scene,
    const std::function<void(PlanBuilder&)>& plan_forward, const std::string& label,
    const std::string& surface_pass = "surface", float min_peak = 0.02f) {
    const FramePlan deferred = make_frame_plan(scene, find_technique(scene.technique));
    PlanBuilder builder(PlanMode::pruned, scene.width, scene.height);
    plan_forward(builder);
    const FramePlan forward = builder.compile();
    ASSERT_EQ(deferred.passes.back().kind, PassKind::fullscreen) << label;
    ASSERT_EQ(forward.passes.back().kind, PassKind::draw_mesh) << label;
    ASSERT_NE(find_pass(deferred, surface_pass), nullptr) << label;
    const Image a = executor.render(scene, deferred);
    const Image b = executor.render(scene, forward);
    EXPECT_EQ(a.rgba, b.rgba) << label;
    EXPECT_GT(*std::max_element(a.rgba.begin(), a.rgba.end()), min_peak) << label;
}

}  // namespace lucent::test
