#pragma once
// The explorer's one input path. GLFW callbacks turn window events into InputEvents and
// hand them to InputRouter::dispatch(); a test's script queue feeds the same dispatch()
// at the top of a frame. dispatch() keeps the pointer state ImGui reads each frame,
// forwards keys, characters and wheel to ImGui's GLFW back end, and gives what ImGui
// does not capture to the view handler (orbit, light drag, zoom).
#include <deque>
#include <functional>
#include <variant>

struct GLFWwindow;

namespace lucent::explorer {

struct MouseMove {
    float x = 0, y = 0;
};  // window coordinates, pixels
struct MouseButton {
    int button = 0;
    bool pressed = false;
};  // 0 left, 1 right
struct Scroll {
    float dy = 0;
};  // wheel notches
struct Key {
    int glfw_key = 0;
    bool pressed = false;
};
struct Character {
    unsigned codepoint = 0;
};
struct WaitFrames {
    int frames = 1;
};  // script only: let frames pass
using InputEvent =
    std::variant<MouseMove, MouseButton, Scroll, Key, Character, WaitFrames>;

// What the view receives when ImGui does not want the event.
struct ViewInput {
    std::function<void(float dx, float dy)> orbit;       // left drag
    std::function<void(float dx, float dy)> move_light;  // right drag
    std::function<void(float notches)> zoom;             // wheel
    std::function<void(int glfw_key)> key;  // key press (not typing in ImGui)
};

class InputRouter {
public:
    // Installs GLFW callbacks on `window` (after ImGui's back end is initialised); they
    // call dispatch(). The router must outlive the window's event polling.
    InputRouter(GLFWwindow* window, ViewInput view);
    ~InputRouter();
    InputRouter(const InputRouter&) = delete;
    InputRouter& operator=(const InputRouter&) = delete;

    void dispatch(const InputEvent& event);
    // Script: events run one per frame (a WaitFrames lets frames pass), from
    // run_script_step() at the top of each frame.
    void enqueue(InputEvent event) { script_.push_back(event); }
    bool script_done() const { return script_.empty(); }
    void run_script_step();
    // Writes pointer position and buttons into ImGui's IO (between the back end's
    // NewFrame and ImGui::NewFrame), so ImGui sees what dispatch() saw.
    void update_imgui_pointer();

private:
    GLFWwindow* window_;
    ViewInput view_;
    std::deque<InputEvent> script_;
    int wait_frames_ = 0;
    float x_ = -1.f, y_ = -1.f;
    bool down_[3] = {false, false, false};
    bool pressed_this_frame_[3] = {false, false, false};
    bool view_drag_[3] = {false, false, false};  // drag began outside ImGui's windows
};

}  // namespace lucent::explorer
