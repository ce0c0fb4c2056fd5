#pragma once
// Sends key presses (and the autopilot's wheel notches and drags) as real X events
// through the XTest extension, to the X server the
// GLFW window lives on, so they travel the same path as a physical keyboard's. It uses
// its own X connection: XTest delays hold up every later request of the connection
// that sent them, and must not stall the window's drawing.
#include <string>
#include <utility>
#include <vector>

struct GLFWwindow;

namespace lucent::study {

class XKeyboard {
public:
    // Throws std::runtime_error (one line) when the window is not on X11 or the server
    // lacks XTest.
    explicit XKeyboard(GLFWwindow* window);
    ~XKeyboard();
    XKeyboard(const XKeyboard&) = delete;
    XKeyboard& operator=(const XKeyboard&) = delete;
    // Moves the pointer into the window and gives it the input focus (no window
    // manager runs under Xvfb to do so). The pointer stays put while button 1 is held:
    // moving it would drag.
    void focus_window();
    // Press and release `key` (names as in autopilot.h; "Shift+Left" holds Shift
    // around the arrow); the release follows after `hold_ms`, as the X server schedules
    // it. Pointer events (is_pointer_event: "WheelUp", "Press:X,Y", ...) are sent as
    // the pointer's: X buttons 4 and 5 for the wheel (GLFW scrolls +1 and -1), motion to
    // window pixels and button 1 for a drag.
    void tap(const std::string& key, int hold_ms = 40);
    // Hands a whole script of (delay ms after the previous key, key) to the X server at
    // once, each press scheduled by the server's XTest delay: the key times are then
    // as exact as the server's millisecond timer, independent of the frame loop (the
    // response-time tests rely on it). Each key is released as soon as it is pressed.
    void play(const std::vector<std::pair<double, std::string>>& script);

private:
    void pointer(const std::string& event);

    GLFWwindow* window_;
    void* display_;
    bool button_down_ = false;  // button 1, between "Press" and "Release"
};

}  // namespace lucent::study
