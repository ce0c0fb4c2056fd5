#include "renderer/gl/errors.h"

#include <epoxy/gl.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace lucent::gl {
namespace {

// The debug messages of this thread's contexts since the last check_errors(): the
// callback is synchronous, so a worker thread never sees another worker's messages.
thread_local std::vector<std::string> t_debug_errors;
constexpr std::size_t kMaxKeptMessages = 8;

const char* error_name(GLenum error) {
    switch (error) {
        case GL_INVALID_ENUM:
            return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE:
            return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION:
            return "GL_INVALID_OPERATION";
        case GL_INVALID_FRAMEBUFFER_OPERATION:
            return "GL_INVALID_FRAMEBUFFER_OPERATION";
        case GL_OUT_OF_MEMORY:
            return "GL_OUT_OF_MEMORY";
        case GL_STACK_UNDERFLOW:
            return "GL_STACK_UNDERFLOW";
        case GL_STACK_OVERFLOW:
            return "GL_STACK_OVERFLOW";
        case GL_CONTEXT_LOST:
            return "GL_CONTEXT_LOST";
        default:
            return "unknown GL error";
    }
}

// One line: drivers may end messages with newlines or embed them.
std::string one_line(std::string text) {
    for (char& c : text)
        if (c == '\n' || c == '\r') c = ' ';
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

void GLAPIENTRY log_debug_message(GLenum source, GLenum type, GLuint /*id*/,
                                  GLenum /*severity*/, GLsizei length,
                                  const GLchar* message, const void* /*user*/) {
    if (source == GL_DEBUG_SOURCE_SHADER_COMPILER) return;  // reported by ShaderError
    if (type != GL_DEBUG_TYPE_ERROR && type != GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR) return;
    if (t_debug_errors.size() >= kMaxKeptMessages) return;
    t_debug_errors.push_back(
        one_line(length >= 0 ? std::string(message, std::size_t(length)) : message));
}

}  // namespace

void check_errors(std::string_view what) {
    std::string names;
    // A lost context may report GL_CONTEXT_LOST forever: stop after a few.
    for (int i = 0; i < 8; ++i) {
        const GLenum error = glGetError();
        if (error == GL_NO_ERROR) break;
        names += (names.empty() ? "" : ", ") + std::string(error_name(error));
        if (error == GL_CONTEXT_LOST) break;
    }
    std::vector<std::string> messages;
    messages.swap(t_debug_errors);
    if (names.empty() && messages.empty()) return;
    std::string text = "GL error in " + std::string(what) + ": ";
    text += names.empty() ? "debug message" : names;
    if (!messages.empty()) text += ": " + messages.front();
    if (messages.size() > 1)
        text += " (and " + std::to_string(messages.size() - 1) + " more)";
    throw GlError(text);
}

void install_debug_messages() {
    if (!epoxy_has_gl_extension("GL_KHR_debug") && epoxy_gl_version() < 43) return;
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(log_debug_message, nullptr);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
}

bool debug_contexts_by_default() {
#ifndef NDEBUG
    return true;
#else
    const char* flag = std::getenv("LUCENT_GL_DEBUG");
    return flag && std::string(flag) == "1";
#endif
}

}  // namespace lucent::gl
