#include "renderer/ui/imgui_window.h"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <filesystem>

namespace lucent::ui {

ImGuiWindow::ImGuiWindow(const ImGuiWindowOptions& options)
    : context_(gl::create_window_context(options.window)) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini beside the participant's database
    const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    if (std::filesystem::exists(font)) {
        io.Fonts->AddFontFromFileTTF(font, options.font_pixels);
    } else {
        io.Fonts->AddFontDefault();
        io.FontGlobalScale = options.font_pixels / 13.f;
    }
    ImGui::StyleColorsDark();
    ImGui::GetStyle().FrameRounding = 6.f;
    // Install ImGui's callbacks chained to any installed before (the runner's key log).
    ImGui_ImplGlfw_InitForOpenGL(context_->window(), true);
    ImGui_ImplOpenGL3_Init("#version 450");
}

ImGuiWindow::~ImGuiWindow() {
    context_->make_current();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

void ImGuiWindow::begin_frame() {
    glfwPollEvents();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
}

void ImGuiWindow::render_imgui() {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void ImGuiWindow::swap() { context_->swap_buffers(); }

}  // namespace lucent::ui
