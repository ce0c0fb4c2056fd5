#pragma once
// Display refresh from buffer-swap timestamps, and dropped frames (GL-free).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace lucent::study {

struct RefreshEstimate {
    std::optional<double> mode_hz;      // the video mode's rate; none when it reports 0
    std::optional<double> measured_hz;  // 1 / median swap interval; none when unknown
    bool mismatch = false;              // measured differs from the mode by more than 5%
    std::string note;                   // one line for the log and the session row
};

// swaps_ns: steady-clock times right after consecutive vsynced swaps. A mode of 0 Hz
// (Xvfb, some virtual displays) means swaps are not paced by a display: the refresh is
// unknown and nothing is invented.
RefreshEstimate estimate_refresh(int mode_refresh_hz, const std::vector<int64_t>& swaps_ns);

// Frames that took longer than 1.5 periods between consecutive swaps count as dropped
// (an interval of k periods drops k-1 frames, rounded).
int dropped_frames(const std::vector<int64_t>& swaps_ns, double refresh_hz);

}  // namespace lucent::study
