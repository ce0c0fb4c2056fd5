#include "renderer/gl/context.h"

#include <epoxy/gl.h>

namespace lucent::gl {

namespace {
std::string gl_string(GLenum name) {
    const auto* text = reinterpret_cast<const char*>(glGetString(name));
    return text ? std::string(text) : std::string("(unavailable)");
}
}  // namespace

GlInfo Context::info() const {
    GlInfo info;
    info.vendor = gl_string(GL_VENDOR);
    info.renderer = gl_string(GL_RENDERER);
    info.version = gl_string(GL_VERSION);
    info.glsl_version = gl_string(GL_SHADING_LANGUAGE_VERSION);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &info.max_texture_size);
    GLint query_bits = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &query_bits);
    info.has_timer_query = query_bits > 0;
    return info;
}

std::vector<std::string> context_provider_names() { return {"egl", "glfw"}; }

std::unique_ptr<Context> create_context(std::string_view provider,
                                        const ContextOptions& options) {
    if (provider == "egl") return create_headless_context(options);
    if (provider == "glfw") return create_window_context(WindowOptions{}, options);
    std::string valid;
    for (const auto& name : context_provider_names())
        valid += (valid.empty() ? "" : ", ") + name;
    throw ContextError("unknown GL context provider '" + std::string(provider) +
                       "' (valid: " + valid + ")");
}

}  // namespace lucent::gl
