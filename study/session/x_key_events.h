#pragma once
// Key presses timestamped where they happen, not when the frame loop gets to them.
//
// Why a thread: the frame loop blocks in the vsync-paced buffer swap, and GLFW delivers
// keys only in glfwPollEvents after it, so a key stamped there is late by up to a frame
// (16.7 ms at 60 Hz) and the error depends on where in the frame it fell. This class
// opens its own connection to the X server of the session window, asks for that
// window's key events (X lets any number of clients select TimedKey on a window) and
// waits for them in a thread blocked in poll(): each press is stamped with the steady
// clock as soon as the server hands it over, whatever the frame loop is doing. The X
// server's own event times are not used: they count milliseconds on the server's clock,
// which is not guaranteed to be the steady clock (and may be a remote machine's).
#include <atomic>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "session/session_flow.h"

struct GLFWwindow;

namespace lucent::study {

class XKeyEvents {
public:
    // Throws std::runtime_error (one line) when the window is not on an X11 display.
    explicit XKeyEvents(GLFWwindow* window);
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
    std::thread thread_;
};

}  // namespace lucent::study
