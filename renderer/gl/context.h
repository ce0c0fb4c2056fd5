#pragma once
// OpenGL context providers behind one interface: a headless one (EGL, surfaceless Mesa
// or an EGL device) that renders into framebuffer objects, and a window one (GLFW).
// Choose by name with create_context(); everything above renderer/gl sees only Context.
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/gl/errors.h"

struct GLFWwindow;

namespace lucent::gl {

// Thrown when a context cannot be created; what() is one line naming the platform
// tried and the reason, e.g. "EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA):
// eglCreateContext failed for OpenGL 9.9 core: EGL_BAD_MATCH".
class ContextError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ContextOptions {
    int gl_major = 4;  // OpenGL core profile version requested
    int gl_minor = 5;
    // A debug context: KHR_debug messages name the failing call in GlError (gl/errors.h).
    bool debug = debug_contexts_by_default();
};

struct WindowOptions {
    int width = 1280;  // window size in screen coordinates (ignored when fullscreen)
    int height = 720;
    bool fullscreen = false;  // full screen on `monitor`, in its current video mode
    int monitor = 0;          // index into glfwGetMonitors()
    bool vsync = true;        // swap interval 1
    bool visible = true;      // hidden windows still render (used by tests)
    std::string title = "Lucent";
};

// Facts about the current context, read with glGetString/glGetIntegerv.
struct GlInfo {
    std::string vendor;
    std::string renderer;
    std::string version;
    std::string glsl_version;
    int max_texture_size = 0;
    bool has_timer_query = false;  // GL_ARB_timer_query (core since 3.3) usable
};

class Context {
public:
    virtual ~Context() = default;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    virtual void make_current() = 0;
    // Provider name as accepted by create_context(): "egl" or "glfw".
    virtual std::string provider() const = 0;
    // Human description of the platform actually used, e.g. "EGL 1.5 surfaceless (Mesa)".
    virtual std::string platform() const = 0;

    GlInfo info() const;

protected:
    Context() = default;
};

class WindowContext : public Context {
public:
    virtual GLFWwindow* window() const = 0;
    virtual void swap_buffers() = 0;
    virtual bool should_close() const = 0;
    // Framebuffer size in pixels (may differ from the window size on HiDPI screens).
    virtual void framebuffer_size(int& width, int& height) const = 0;
};

std::unique_ptr<Context> create_headless_context(const ContextOptions& options = {});
std::unique_ptr<WindowContext> create_window_context(const WindowOptions& window,
                                                     const ContextOptions& options = {});

// The provider names create_context() accepts, for help text and error messages.
std::vector<std::string> context_provider_names();
// "egl" gives a headless context; "glfw" a window with default WindowOptions.
// An unknown name throws ContextError listing the valid names.
std::unique_ptr<Context> create_context(std::string_view provider,
                                        const ContextOptions& options = {});

}  // namespace lucent::gl
