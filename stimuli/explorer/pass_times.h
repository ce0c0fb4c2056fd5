#pragma once
// The status bar's per-pass times: each pass of the last frame with its time, or
// "cached" when its inputs had not changed and it was not re-run (a slider re-runs only
// the passes it touches). No ImGui, so it is tested as text.
#include <string>

#include "renderer/gl/frame_executor.h"

namespace lucent::explorer {

// "GPU pass times (timer queries): front_depth cached  shade 1.23 ms  (1 of 2 passes
// ran)".
std::string pass_times_text(const gl::FrameTimings& timings);

}  // namespace lucent::explorer
