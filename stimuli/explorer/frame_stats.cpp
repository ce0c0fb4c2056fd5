#include "stimuli/explorer/frame_stats.h"

#include <algorithm>

namespace lucent::explorer {

void FrameStats::add(double end_seconds, double ms) {
    frames_.push_back({end_seconds, ms});
    while (frames_.size() > 1 &&
           frames_.front().end_seconds <= end_seconds - window_seconds_)
        frames_.pop_front();
}

FrameTimeSummary FrameStats::summary() const {
    FrameTimeSummary s;
    if (frames_.empty()) return s;
    s.min_ms = s.max_ms = frames_.front().ms;
    double sum = 0.0;
    for (const Frame& f : frames_) {
        s.min_ms = std::min(s.min_ms, f.ms);
        s.max_ms = std::max(s.max_ms, f.ms);
        sum += f.ms;
    }
    s.frames = static_cast<int>(frames_.size());
    s.mean_ms = sum / s.frames;
    return s;
}

}  // namespace lucent::explorer
