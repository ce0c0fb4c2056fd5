// Window contexts through GLFW: windowed or full screen on a chosen monitor, vsync.
#include <epoxy/gl.h>
// GLFW after epoxy: GLFW must not pull in a second GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <mutex>
#include <string>

#include "renderer/gl/context.h"

namespace lucent::gl {
namespace {

std::string g_last_glfw_error;

void record_glfw_error(int /*code*/, const char* description) {
    g_last_glfw_error = description ? description : "unknown GLFW error";
}

// glfwInit once per process; glfwTerminate at exit so repeated windows stay cheap.
void ensure_glfw_initialised() {
    static bool ok = false;
    static std::once_flag once;
    std::call_once(once, [] {
        glfwSetErrorCallback(record_glfw_error);
        ok = glfwInit() == GLFW_TRUE;
        if (ok) std::atexit(glfwTerminate);
    });
    if (!ok) {
        throw ContextError(
            "GLFW (X11/Wayland window): glfwInit failed: " + g_last_glfw_error +
            " (no display? run under xvfb-run, or use the headless commands)");
    }
}

class GlfwContext final : public WindowContext {
public:
    GlfwContext(GLFWwindow* window, std::string platform)
        : window_(window), platform_(std::move(platform)) {}
    ~GlfwContext() override { glfwDestroyWindow(window_); }
    void make_current() override { glfwMakeContextCurrent(window_); }
    std::string provider() const override { return "glfw"; }
    std::string platform() const override { return platform_; }
    GLFWwindow* window() const override { return window_; }
    void swap_buffers() override { glfwSwapBuffers(window_); }
    bool should_close() const override { return glfwWindowShouldClose(window_); }
    void framebuffer_size(int& width, int& height) const override {
        glfwGetFramebufferSize(window_, &width, &height);
    }

private:
    GLFWwindow* window_;
    std::string platform_;
};

}  // namespace

std::unique_ptr<WindowContext> create_window_context(const WindowOptions& window,
                                                     const ContextOptions& options) {
    ensure_glfw_initialised();
    const std::string label = std::string("GLFW ") + glfwGetVersionString();

    GLFWmonitor* monitor = nullptr;
    int width = window.width, height = window.height;
    if (window.fullscreen) {
        int count = 0;
        GLFWmonitor** monitors = glfwGetMonitors(&count);
        if (count == 0) throw ContextError(label + ": no monitor is connected");
        if (window.monitor < 0 || window.monitor >= count)
            throw ContextError(label + ": monitor " + std::to_string(window.monitor) +
                               " does not exist (" + std::to_string(count) +
                               " connected)");
        monitor = monitors[window.monitor];
        const GLFWvidmode* mode = glfwGetVideoMode(monitor);
        width = mode->width;
        height = mode->height;
        glfwWindowHint(GLFW_RED_BITS, mode->redBits);
        glfwWindowHint(GLFW_GREEN_BITS, mode->greenBits);
        glfwWindowHint(GLFW_BLUE_BITS, mode->blueBits);
        glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, options.gl_major);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, options.gl_minor);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, options.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, window.visible ? GLFW_TRUE : GLFW_FALSE);

    g_last_glfw_error.clear();
    GLFWwindow* handle =
        glfwCreateWindow(width, height, window.title.c_str(), monitor, nullptr);
    glfwDefaultWindowHints();
    if (!handle) {
        throw ContextError(label + ": glfwCreateWindow failed for OpenGL " +
                           std::to_string(options.gl_major) + "." +
                           std::to_string(options.gl_minor) +
                           " core: " + g_last_glfw_error);
    }
    glfwMakeContextCurrent(handle);
    glfwSwapInterval(window.vsync ? 1 : 0);
    if (options.debug) install_debug_messages();
    return std::make_unique<GlfwContext>(handle, label);
}

}  // namespace lucent::gl
