#pragma once
// Key presses timestamped where they happen, not when the frame loop gets to them.
//
// Why: the frame loop blocks in the vsync-paced buffer swap, and GLFW delivers keys only
// in glfwPollEvents after it, so a key stamped there is late by up to a frame (16.7 ms
// at 60 Hz), by an amount that depends on where in the frame it fell.
//
// How: this class opens its own connection to the X server of the session window, asks
// for that window's key events (X lets any number of clients select KeyPress on a
// window) and waits for them in a thread blocked in poll(), independent of the frame
// loop. Each press gets two times: when the thread received it (steady clock, sub-ms,
// but late if the thread was not scheduled at once) and the X server's own event time
// (whole ms, on the server's clock). A local X.Org server (Xorg, Xvfb, Xwayland) counts
// that time in ms of CLOCK_MONOTONIC, the steady clock's own base; this is checked per
// event (the receipt must follow the event time by less than a second, modulo the 32-bit
// wrap). When it holds, the press happened in [event ms, event ms + 1 ms), so the stamp
// is the receipt time if it lies in that millisecond, else the middle of it: never more
// than 1 ms off, however late the thread woke. When it does not hold (a remote server),
// the receipt time is used. (key_press_time in frame_timing.h, unit-tested.)
#include <cstdint>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "study/session/session_flow.h"

struct GLFWwindow;

namespace lucent::study {

class XKeyEvents {
public:
    // Throws std::runtime_error (one line) when the window is not on an X11 display.
    // `trace_path`: when set, one line per press, "SERVER_MS RECEIPT_NS STAMP_NS"
    // (tests).
    explicit XKeyEvents(GLFWwindow* window, const std::string& trace_path = "");
    ~XKeyEvents();
    XKeyEvents(const XKeyEvents&) = delete;
    XKeyEvents& operator=(const XKeyEvents&) = delete;

    // The presses since the last call, oldest first. Auto-repeat is not a press.
    std::vector<TimedKey> take();

private:
    void loop();

    void* display_ = nullptr;
    int wake_[2] = {-1, -1};  // a pipe: a byte stops the thread
    std::mutex mutex_;
    std::vector<TimedKey> pending_;
    std::ofstream trace_;
    std::thread thread_;
};

}  // namespace lucent::study
