#pragma once
// Display refresh from buffer-swap timestamps, dropped frames, and key press times from
// X event times (GL-free).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace lucent::study {

// Now on the steady clock, in ns: what swaps and key presses are stamped with (the
// runner and XKeyEvents' thread), so that the two compare.
int64_t steady_now_ns();

struct RefreshEstimate {
    std::optional<double> mode_hz;      // the video mode's rate; none when it reports 0
    std::optional<double> measured_hz;  // 1 / median swap interval; none when unknown
    bool mismatch = false;              // measured differs from the mode by more than 5%
    std::string note;                   // one line for the log and the session row
};

// swaps_ns: steady-clock times right after consecutive vsynced swaps. A mode of 0 Hz
// (Xvfb, some virtual displays) means swaps are not paced by a display: the refresh is
// unknown and nothing is invented.
RefreshEstimate estimate_refresh(int mode_refresh_hz,
                                 const std::vector<int64_t>& swaps_ns);

// Frames that took longer than 1.5 periods between consecutive swaps count as dropped
// (an interval of k periods drops k-1 frames, rounded).
int dropped_frames(const std::vector<int64_t>& swaps_ns, double refresh_hz);

// The steady-clock time of a key press received at `receipt_ns` whose X event time is
// `server_ms` (the server's 32-bit millisecond counter). When the server counts in ms of
// the steady clock's base (local X.Org servers: CLOCK_MONOTONIC), recognised by the
// receipt following the event time by under 1 s, the press lies in
// [server_ms, server_ms + 1 ms): the receipt time when it falls in that millisecond,
// else its middle. Otherwise the receipt time. See x_key_events.h for why.
int64_t key_press_time(int64_t receipt_ns, uint32_t server_ms);

}  // namespace lucent::study
