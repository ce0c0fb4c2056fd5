#pragma once
// Sends key presses as real X events through the XTest extension, to the X server the
// GLFW window lives on, so they travel the same path as a physical keyboard's.
#include <string>

struct GLFWwindow;

namespace lucent::study {

class XKeyboard {
public:
    // Throws std::runtime_error (one line) when the window is not on X11 or the server
    // lacks XTest.
    explicit XKeyboard(GLFWwindow* window);
    // Moves the pointer into the window and gives it the input focus (no window
    // manager runs under Xvfb to do so).
    void focus_window();
    // Press and release `key` (names as in autopilot.h); the release follows after
    // `hold_ms`, as the X server schedules it.
    void tap(const std::string& key, int hold_ms = 40);

private:
    GLFWwindow* window_;
    void* display_;
};

}  // namespace lucent::study
