#include "study/session/frame_timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace lucent::study {

int64_t steady_now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

RefreshEstimate estimate_refresh(int mode_refresh_hz,
                                 const std::vector<int64_t>& swaps_ns) {
    RefreshEstimate e;
    if (mode_refresh_hz <= 0) {
        e.note =
            "refresh unknown: the video mode reports 0 Hz (e.g. Xvfb), so swaps are not "
            "paced by a display; recorded as NULL";
        return e;
    }
    e.mode_hz = mode_refresh_hz;
    std::vector<int64_t> intervals;
    for (size_t i = 1; i < swaps_ns.size(); ++i)
        if (swaps_ns[i] > swaps_ns[i - 1])
            intervals.push_back(swaps_ns[i] - swaps_ns[i - 1]);
    if (intervals.size() < 10) {
        e.note = "refresh not measured: fewer than 10 swap intervals";
        return e;
    }
    std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2,
                     intervals.end());
    const double median_ns = static_cast<double>(intervals[intervals.size() / 2]);
    e.measured_hz = 1e9 / median_ns;
    const double rel = std::abs(*e.measured_hz - mode_refresh_hz) / mode_refresh_hz;
    e.mismatch = rel > 0.05;
    std::ostringstream note;
    note.precision(4);
    note << "measured refresh " << *e.measured_hz << " Hz, video mode " << mode_refresh_hz
         << " Hz";
    if (e.mismatch) note << ": WARNING, they differ by more than 5% (is vsync off?)";
    e.note = note.str();
    return e;
}

int dropped_frames(const std::vector<int64_t>& swaps_ns, double refresh_hz) {
    if (!(refresh_hz > 0)) return 0;
    const double period = 1e9 / refresh_hz;
    int dropped = 0;
    for (size_t i = 1; i < swaps_ns.size(); ++i) {
        const double periods = (swaps_ns[i] - swaps_ns[i - 1]) / period;
        if (periods > 1.5) dropped += static_cast<int>(std::lround(periods)) - 1;
    }
    return dropped;
}

int64_t key_press_time(int64_t receipt_ns, uint32_t server_ms) {
    constexpr int64_t kMs = 1'000'000;
    // How far the receipt is behind the event, in ms, modulo the 32-bit counter.
    const uint32_t behind = static_cast<uint32_t>(receipt_ns / kMs) - server_ms;
    if (behind >= 1000) return receipt_ns;  // another clock: only the receipt is known
    const int64_t event_ms_start = (receipt_ns / kMs - behind) * kMs;
    if (receipt_ns < event_ms_start + kMs) return receipt_ns;
    return event_ms_start + kMs / 2;
}

}  // namespace lucent::study
