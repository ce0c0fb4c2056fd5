// Headless OpenGL through EGL with no window system: Mesa's surfaceless platform first
// (llvmpipe on machines without a GPU), then an EGL device (a GPU vendor's driver).
// Rendering goes to framebuffer objects; the context has no default framebuffer.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstring>
#include <string>

#include "renderer/gl/context.h"

namespace lucent::gl {
namespace {

const char* egl_error_name(EGLint error) {
    switch (error) {
        case EGL_SUCCESS:
            return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED:
            return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS:
            return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC:
            return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE:
            return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG:
            return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT:
            return "EGL_BAD_CONTEXT";
        case EGL_BAD_CURRENT_SURFACE:
            return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY:
            return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH:
            return "EGL_BAD_MATCH";
        case EGL_BAD_NATIVE_PIXMAP:
            return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW:
            return "EGL_BAD_NATIVE_WINDOW";
        case EGL_BAD_PARAMETER:
            return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE:
            return "EGL_BAD_SURFACE";
        case EGL_CONTEXT_LOST:
            return "EGL_CONTEXT_LOST";
        default:
            return "unknown EGL error";
    }
}

bool has_extension(const char* list, const char* name) {
    if (!list) return false;
    const size_t len = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += len)
        if ((p == list || p[-1] == ' ') && (p[len] == ' ' || p[len] == '\0')) return true;
    return false;
}

class EglContext final : public Context {
public:
    EglContext(EGLDisplay display, EGLContext context, std::string platform)
        : display_(display), context_(context), platform_(std::move(platform)) {}
    ~EglContext() override {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        eglTerminate(display_);
    }
    void make_current() override {
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            throw ContextError(
                platform_ + ": eglMakeCurrent failed: " + egl_error_name(eglGetError()));
    }
    std::string provider() const override { return "egl"; }
    std::string platform() const override { return platform_; }

private:
    EGLDisplay display_;
    EGLContext context_;
    std::string platform_;
};

// Creates a core-profile context on an initialised display, or throws naming `label`.
std::unique_ptr<Context> create_on_display(EGLDisplay display, const std::string& label,
                                           const ContextOptions& options) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor))
        throw ContextError(label +
                           ": eglInitialize failed: " + egl_error_name(eglGetError()));
    const std::string platform =
        "EGL " + std::to_string(major) + "." + std::to_string(minor) + " " + label;
    auto fail = [&](const std::string& what) -> std::unique_ptr<Context> {
        const std::string reason = egl_error_name(eglGetError());
        eglTerminate(display);
        throw ContextError(platform + ": " + what + ": " + reason);
    };
    const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
        eglTerminate(display);
        throw ContextError(platform + ": EGL_KHR_surfaceless_context is not supported");
    }
    if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI(EGL_OPENGL_API) failed");

    // Surfaceless displays offer pbuffer configs only; the default (window) would match
    // none.
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
                                     EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint num_configs = 0;
    if (!eglChooseConfig(display, config_attribs, &config, 1, &num_configs) ||
        num_configs == 0)
        return fail("no EGL config renders OpenGL");

    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                      options.gl_major,
                                      EGL_CONTEXT_MINOR_VERSION,
                                      options.gl_minor,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_CONTEXT_OPENGL_DEBUG,
                                      options.debug ? EGL_TRUE : EGL_FALSE,
                                      EGL_NONE};
    EGLContext context =
        eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
    if (context == EGL_NO_CONTEXT)
        return fail("eglCreateContext failed for OpenGL " +
                    std::to_string(options.gl_major) + "." +
                    std::to_string(options.gl_minor) + " core");
    auto result = std::make_unique<EglContext>(display, context, platform);
    result->make_current();
    if (options.debug) install_debug_messages();
    return result;
}

}  // namespace

std::unique_ptr<Context> create_headless_context(const ContextOptions& options) {
    const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_extension(client_extensions, "EGL_EXT_platform_base"))
        throw ContextError(
            "EGL: EGL_EXT_platform_base is missing; cannot pick a headless platform");

    std::string reasons;
    if (has_extension(client_extensions, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA,
                                                      EGL_DEFAULT_DISPLAY, nullptr);
        const std::string label = "surfaceless (EGL_PLATFORM_SURFACELESS_MESA)";
        if (display != EGL_NO_DISPLAY) {
            try {
                return create_on_display(display, label, options);
            } catch (const ContextError& e) {
                reasons = e.what();
            }
        } else {
            reasons = "EGL " + label + ": no display: " + egl_error_name(eglGetError());
        }
    } else {
        reasons = "EGL_MESA_platform_surfaceless is not supported";
    }

    // A GPU vendor's EGL (no Mesa surfaceless platform): the first EGL device.
    if (has_extension(client_extensions, "EGL_EXT_platform_device") &&
        has_extension(client_extensions, "EGL_EXT_device_enumeration")) {
        EGLDeviceEXT devices[8];
        EGLint count = 0;
        if (eglQueryDevicesEXT(8, devices, &count) && count > 0) {
            EGLDisplay display =
                eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
            if (display != EGL_NO_DISPLAY) {
                try {
                    return create_on_display(display, "device (EGL_PLATFORM_DEVICE_EXT)",
                                             options);
                } catch (const ContextError& e) {
                    reasons += std::string("; ") + e.what();
                }
            }
        }
    }
    throw ContextError(reasons);
}

}  // namespace lucent::gl
