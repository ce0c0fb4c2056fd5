#pragma once
// One window with Dear ImGui on top: the GLFW context from renderer/gl plus the ImGui
// GLFW/OpenGL3 back ends, a readable font, and frame begin/end. Shared by the session
// runner and the explorer so window and ImGui set-up live in one place.
#include <imgui.h>

#include <memory>
#include <string>

#include "renderer/gl/context.h"
#include "renderer/gl/objects.h"

namespace lucent::ui {

struct ImGuiWindowOptions {
    gl::WindowOptions window;
    float font_pixels = 26.f;  // text size; DejaVu Sans when installed, else ImGui's own
};

class ImGuiWindow {
public:
    // Throws gl::ContextError (one line) when no window can be opened.
    explicit ImGuiWindow(const ImGuiWindowOptions& options);
    ~ImGuiWindow();
    ImGuiWindow(const ImGuiWindow&) = delete;
    ImGuiWindow& operator=(const ImGuiWindow&) = delete;

    gl::WindowContext& context() { return *context_; }
    GLFWwindow* glfw() const { return context_->window(); }
    void framebuffer_size(int& width, int& height) const {
        context_->framebuffer_size(width, height);
    }

    void begin_frame();   // polls events, starts an ImGui frame
    void render_imgui();  // draws the ImGui frame into the back buffer
    void swap();          // presents the back buffer

private:
    std::unique_ptr<gl::WindowContext> context_;
};

// ImGui's handle for a GL texture (the OpenGL3 back end takes the texture name).
inline ImTextureID imgui_texture(const gl::Texture& texture) {
    return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture.id()));
}

}  // namespace lucent::ui
