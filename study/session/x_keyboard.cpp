#include "study/session/x_keyboard.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/Xlib.h>
#include <X11/extensions/XTest.h>
#include <X11/keysym.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "study/session/autopilot.h"

// GLFW's X11 native access, declared here because glfw3native.h also pulls in Xrandr
// headers (libxrandr-dev) that nothing else needs.
extern "C" Display* glfwGetX11Display(void);
extern "C" Window glfwGetX11Window(GLFWwindow* window);

namespace lucent::study {

namespace {

// "Shift+KEY": KEY held with Shift (an adjustment's fine step).
bool shifted(std::string& key) {
    if (key.rfind("Shift+", 0) != 0) return false;
    key = key.substr(6);
    return true;
}

KeyCode keycode(Display* dpy, const std::string& key) {
    static const std::map<std::string, KeySym> kSyms = {{"1", XK_1},
                                                        {"2", XK_2},
                                                        {"3", XK_3},
                                                        {"4", XK_4},
                                                        {"5", XK_5},
                                                        {"6", XK_6},
                                                        {"7", XK_7},
                                                        {"8", XK_8},
                                                        {"9", XK_9},
                                                        {"Enter", XK_Return},
                                                        {"Escape", XK_Escape},
                                                        {"Left", XK_Left},
                                                        {"Right", XK_Right},
                                                        {"Up", XK_Up},
                                                        {"Down", XK_Down},
                                                        {"Q", XK_q},
                                                        {"R", XK_r}};
    const auto it = kSyms.find(key);
    if (it == kSyms.end())
        throw std::runtime_error("autopilot: unknown key '" + key + "'");
    return XKeysymToKeycode(dpy, it->second);
}

}  // namespace

XKeyboard::XKeyboard(GLFWwindow* window) : window_(window) {
    Display* glfw_display = glfwGetX11Display();
    if (!glfw_display)
        throw std::runtime_error(
            "autopilot needs an X11 display (XTest); none is in use");
    display_ = XOpenDisplay(DisplayString(glfw_display));
    if (!display_)
        throw std::runtime_error("autopilot: cannot open a second X connection");
    int event_base, error_base, major, minor;
    if (!XTestQueryExtension(static_cast<Display*>(display_), &event_base, &error_base,
                             &major, &minor)) {
        XCloseDisplay(static_cast<Display*>(display_));
        throw std::runtime_error("autopilot: the X server has no XTest extension");
    }
}

XKeyboard::~XKeyboard() { XCloseDisplay(static_cast<Display*>(display_)); }

void XKeyboard::focus_window() {
    Display* dpy = static_cast<Display*>(display_);
    int x = 0, y = 0, w = 0, h = 0;
    glfwGetWindowPos(window_, &x, &y);
    glfwGetWindowSize(window_, &w, &h);
    if (!button_down_) XTestFakeMotionEvent(dpy, -1, x + w / 2, y + h / 2, CurrentTime);
    XSetInputFocus(dpy, glfwGetX11Window(window_), RevertToParent, CurrentTime);
    XFlush(dpy);
}

void XKeyboard::pointer(const std::string& event) {
    Display* dpy = static_cast<Display*>(display_);
    if (event == "WheelUp" || event == "WheelDown") {
        const unsigned button = event == "WheelUp" ? 4 : 5;
        XTestFakeButtonEvent(dpy, button, True, CurrentTime);
        XTestFakeButtonEvent(dpy, button, False, CurrentTime);
    } else if (event == "Release") {
        XTestFakeButtonEvent(dpy, 1, False, CurrentTime);
        button_down_ = false;
    } else {  // "Press:X,Y" or "Move:X,Y", in window pixels
        const size_t colon = event.find(':'), comma = event.find(',', colon);
        if (colon == std::string::npos || comma == std::string::npos)
            throw std::runtime_error("autopilot: bad pointer event '" + event + "'");
        const int px = std::stoi(event.substr(colon + 1, comma - colon - 1));
        const int py = std::stoi(event.substr(comma + 1));
        int wx = 0, wy = 0;
        glfwGetWindowPos(window_, &wx, &wy);
        XTestFakeMotionEvent(dpy, -1, wx + px, wy + py, CurrentTime);
        if (event.rfind("Press:", 0) == 0) {
            XTestFakeButtonEvent(dpy, 1, True, CurrentTime);
            button_down_ = true;
        }
    }
    XFlush(dpy);
}

void XKeyboard::tap(const std::string& name, int hold_ms) {
    Display* dpy = static_cast<Display*>(display_);
    if (is_pointer_event(name)) return pointer(name);
    std::string key = name;
    const bool shift = shifted(key);
    const KeyCode code = keycode(dpy, key);
    const KeyCode shift_code = XKeysymToKeycode(dpy, XK_Shift_L);
    if (shift) XTestFakeKeyEvent(dpy, shift_code, True, CurrentTime);
    XTestFakeKeyEvent(dpy, code, True, CurrentTime);
    XTestFakeKeyEvent(dpy, code, False, static_cast<unsigned long>(hold_ms));
    if (shift) XTestFakeKeyEvent(dpy, shift_code, False, CurrentTime);
    XFlush(dpy);
}

void XKeyboard::play(const std::vector<std::pair<double, std::string>>& script) {
    Display* dpy = static_cast<Display*>(display_);
    // Each press waits its delay after the previous press on the server's timer, and is
    // released at once: one timer per interval, so the intervals keep the timer's 1 ms
    // steps (a held key would put the release's timer inside the next interval).
    // Delays are rounded from the running total, so they never drift.
    double t = 0;
    long sent = 0;  // ms from the start of the last press sent
    const KeyCode shift_code = XKeysymToKeycode(dpy, XK_Shift_L);
    for (const auto& [delay, name] : script) {
        const long at = std::lround(t += delay);
        std::string key = name;
        const bool shift = shifted(key);
        const KeyCode code = keycode(dpy, key);
        // Shift goes down with the key's delay, the key right after it.
        if (shift)
            XTestFakeKeyEvent(dpy, shift_code, True,
                              static_cast<unsigned long>(at - sent));
        XTestFakeKeyEvent(dpy, code, True,
                          shift ? CurrentTime : static_cast<unsigned long>(at - sent));
        XTestFakeKeyEvent(dpy, code, False, CurrentTime);
        if (shift) XTestFakeKeyEvent(dpy, shift_code, False, CurrentTime);
        sent = at;
    }
    XFlush(dpy);
}

}  // namespace lucent::study
