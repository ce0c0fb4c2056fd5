#include "stimuli/explorer/pass_times.h"

#include <cstdio>

namespace lucent::explorer {

std::string pass_times_text(const gl::FrameTimings& timings) {
    std::string line = timings.gpu_timer ? "GPU pass times (timer queries):"
                                         : "pass times (wall, glFinish):";
    std::size_t ran = 0;
    for (const auto& pass : timings.passes) {
        char text[128];
        if (pass.cached) {
            std::snprintf(text, sizeof text, "  %s cached", pass.pass.c_str());
        } else {
            std::snprintf(text, sizeof text, "  %s %.2f ms", pass.pass.c_str(),
                          pass.milliseconds);
            ++ran;
        }
        line += text;
    }
    line += "  (" + std::to_string(ran) + " of " + std::to_string(timings.passes.size()) +
            " passes ran)";
    return line;
}

}  // namespace lucent::explorer
