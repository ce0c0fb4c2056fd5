#pragma once
// Frame times over a sliding window (the last second by default): min, mean and max for
// the status bar, as the thesis tool showed its frame rate. GL-free.
#include <deque>

namespace lucent::explorer {

struct FrameTimeSummary {
    double min_ms = 0.0, mean_ms = 0.0, max_ms = 0.0;
    int frames = 0;
};

class FrameStats {
public:
    explicit FrameStats(double window_seconds = 1.0) : window_seconds_(window_seconds) {}
    // One frame that ended at `end_seconds` (a monotonic clock) and took `ms`.
    void add(double end_seconds, double ms);
    // The frames that ended within the window before the latest one.
    FrameTimeSummary summary() const;

private:
    struct Frame {
        double end_seconds, ms;
    };
    double window_seconds_;
    std::deque<Frame> frames_;
};

}  // namespace lucent::explorer
