#include "study/session/x_key_events.h"

#include "study/session/frame_timing.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/XKBlib.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>
#include <poll.h>
#include <unistd.h>

#include <bitset>
#include <optional>
#include <stdexcept>

// GLFW's X11 native access (see x_keyboard.cpp for why it is declared here).
extern "C" Display* glfwGetX11Display(void);
extern "C" Window glfwGetX11Window(GLFWwindow* window);

namespace lucent::study {
namespace {

std::optional<TimedKey> press_for(XKeyEvent& event, int64_t t_ns) {
    KeySym sym = XLookupKeysym(&event, 0);
    if (IsKeypadKey(sym) || (sym >= XK_KP_Home && sym <= XK_KP_Delete))
        sym = XLookupKeysym(&event, 1);  // keypad digits whatever the NumLock state
    if (sym >= XK_1 && sym <= XK_9) return TimedKey{Key::Digit, int(sym - XK_0), t_ns};
    if (sym >= XK_KP_1 && sym <= XK_KP_9)
        return TimedKey{Key::Digit, int(sym - XK_KP_0), t_ns};
    switch (sym) {
        case XK_Return:
        case XK_KP_Enter:
            return TimedKey{Key::Enter, 0, t_ns};
        case XK_Escape:
            return TimedKey{Key::Escape, 0, t_ns};
        case XK_Left:
            return TimedKey{Key::Left, 0, t_ns};
        case XK_Right:
            return TimedKey{Key::Right, 0, t_ns};
        case XK_Up:
            return TimedKey{Key::Up, 0, t_ns};
        case XK_Down:
            return TimedKey{Key::Down, 0, t_ns};
        case XK_q:
            return TimedKey{Key::Quit, 0, t_ns};
        case XK_r:
            return TimedKey{Key::Resume, 0, t_ns};
        case XK_n:
            return TimedKey{Key::Decline, 0, t_ns};
        default:
            return std::nullopt;
    }
}

}  // namespace

XKeyEvents::XKeyEvents(GLFWwindow* window, const std::string& trace_path) {
    if (!trace_path.empty()) {
        trace_.open(trace_path);
        if (!trace_)
            throw std::runtime_error(trace_path + ": cannot write the key trace");
    }
    Display* glfw_display = glfwGetX11Display();
    if (!glfw_display)
        throw std::runtime_error("key timing needs an X11 display; none is in use");
    Display* dpy = XOpenDisplay(DisplayString(glfw_display));
    if (!dpy)
        throw std::runtime_error("cannot open a second connection to the X display");
    display_ = dpy;
    // Auto-repeat then sends presses without releases between them: a held key is one
    // press.
    XkbSetDetectableAutoRepeat(dpy, True, nullptr);
    XSelectInput(dpy, glfwGetX11Window(window),
                 KeyPressMask | KeyReleaseMask | FocusChangeMask);
    XSync(dpy, False);
    if (pipe(wake_) != 0) {
        XCloseDisplay(dpy);
        throw std::runtime_error("cannot create the key thread's pipe");
    }
    thread_ = std::thread([this] { loop(); });
}

XKeyEvents::~XKeyEvents() {
    const char stop = 1;
    if (write(wake_[1], &stop, 1) != 1) {
    }
    thread_.join();
    close(wake_[0]);
    close(wake_[1]);
    XCloseDisplay(static_cast<Display*>(display_));
}

std::vector<TimedKey> XKeyEvents::take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<TimedKey> out;
    out.swap(pending_);
    return out;
}

void XKeyEvents::loop() {
    Display* dpy = static_cast<Display*>(display_);
    std::bitset<256> down;  // keycodes held: a press while held is auto-repeat
    pollfd fds[2] = {{ConnectionNumber(dpy), POLLIN, 0}, {wake_[0], POLLIN, 0}};
    for (;;) {
        // Events already read into Xlib's queue need no wait.
        if (XEventsQueued(dpy, QueuedAfterFlush) == 0) {
            if (poll(fds, 2, -1) < 0) continue;
            if (fds[1].revents) return;
            if (XEventsQueued(dpy, QueuedAfterReading) == 0) continue;
        }
        const int64_t t = steady_now_ns();  // as soon as the server's bytes are here
        XEvent event;
        XNextEvent(dpy, &event);
        if (event.type == FocusIn || event.type == FocusOut) {
            down.reset();  // releases while unfocused never arrive
        } else if (event.type == KeyRelease) {
            down.reset(event.xkey.keycode & 0xFF);
        } else if (event.type == KeyPress) {
            const unsigned code = event.xkey.keycode & 0xFF;
            if (down.test(code)) continue;
            down.set(code);
            const int64_t stamped =
                key_press_time(t, static_cast<uint32_t>(event.xkey.time));
            if (auto press = press_for(event.xkey, stamped)) {
                // Shift held with it (the state before the event): an adjustment's
                // fine step.
                press->shift = (event.xkey.state & ShiftMask) != 0;
                std::lock_guard<std::mutex> lock(mutex_);
                pending_.push_back(*press);
                if (trace_.is_open())
                    trace_ << event.xkey.time << " " << t << " " << stamped << std::endl;
            }
        }
    }
}

}  // namespace lucent::study
