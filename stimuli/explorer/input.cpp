#include "stimuli/explorer/input.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>

#include <cfloat>

namespace lucent::explorer {
namespace {

InputRouter* router_of(GLFWwindow* window) {
    return static_cast<InputRouter*>(glfwGetWindowUserPointer(window));
}

}  // namespace

InputRouter::InputRouter(GLFWwindow* window, ViewInput view)
    : window_(window), view_(std::move(view)) {
    glfwSetWindowUserPointer(window, this);
    // Replaces the back end's callbacks: dispatch() forwards to them itself.
    glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
        router_of(w)->dispatch(MouseMove{static_cast<float>(x), static_cast<float>(y)});
    });
    glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
        router_of(w)->dispatch(MouseButton{button, action == GLFW_PRESS});
    });
    glfwSetScrollCallback(window, [](GLFWwindow* w, double, double dy) {
        router_of(w)->dispatch(Scroll{static_cast<float>(dy)});
    });
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
        if (action != GLFW_REPEAT) router_of(w)->dispatch(Key{key, action == GLFW_PRESS});
    });
    glfwSetCharCallback(
        window, [](GLFWwindow* w, unsigned c) { router_of(w)->dispatch(Character{c}); });
}

InputRouter::~InputRouter() {
    glfwSetCursorPosCallback(window_, nullptr);
    glfwSetMouseButtonCallback(window_, nullptr);
    glfwSetScrollCallback(window_, nullptr);
    glfwSetKeyCallback(window_, nullptr);
    glfwSetCharCallback(window_, nullptr);
    glfwSetWindowUserPointer(window_, nullptr);
}

void InputRouter::dispatch(const InputEvent& event) {
    const ImGuiIO& io = ImGui::GetIO();
    if (const auto* move = std::get_if<MouseMove>(&event)) {
        const float dx = x_ < 0.f ? 0.f : move->x - x_,
                    dy = y_ < 0.f ? 0.f : move->y - y_;
        x_ = move->x;
        y_ = move->y;
        if (view_drag_[0] && view_.orbit) view_.orbit(dx, dy);
        if (view_drag_[1] && view_.move_light) view_.move_light(dx, dy);
    } else if (const auto* button = std::get_if<MouseButton>(&event)) {
        if (button->button < 0 || button->button > 2) return;
        down_[button->button] = button->pressed;
        if (button->pressed) pressed_this_frame_[button->button] = true;
        // A drag belongs to the view only when it starts outside ImGui's windows.
        view_drag_[button->button] = button->pressed && !io.WantCaptureMouse;
    } else if (const auto* scroll = std::get_if<Scroll>(&event)) {
        ImGui_ImplGlfw_ScrollCallback(window_, 0.0, scroll->dy);
        if (!io.WantCaptureMouse && view_.zoom) view_.zoom(scroll->dy);
    } else if (const auto* key = std::get_if<Key>(&event)) {
        ImGui_ImplGlfw_KeyCallback(window_, key->glfw_key, 0,
                                   key->pressed ? GLFW_PRESS : GLFW_RELEASE, 0);
        if (key->pressed && !io.WantCaptureKeyboard && view_.key)
            view_.key(key->glfw_key);
    } else if (const auto* character = std::get_if<Character>(&event)) {
        ImGui_ImplGlfw_CharCallback(window_, character->codepoint);
    }
}

void InputRouter::run_script_step() {
    if (wait_frames_ > 0) {
        --wait_frames_;
        return;
    }
    if (script_.empty()) return;
    const InputEvent event = script_.front();
    script_.pop_front();
    if (const auto* wait = std::get_if<WaitFrames>(&event))
        wait_frames_ = wait->frames - 1;
    else
        dispatch(event);
}

void InputRouter::update_imgui_pointer() {
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = x_ < 0.f ? ImVec2(-FLT_MAX, -FLT_MAX) : ImVec2(x_, y_);
    // A press and release within one frame still counts as held for that frame.
    for (int i = 0; i < 3; ++i) {
        io.MouseDown[i] = down_[i] || pressed_this_frame_[i];
        pressed_this_frame_[i] = false;
    }
}

}  // namespace lucent::explorer
