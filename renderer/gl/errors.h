#pragma once
// GL errors made loud: glGetError drained at pass boundaries, uploads and read-backs, and
// in debug contexts the KHR_debug message of the failing call, turned into a one-line
// GlError naming what was being done ("GL error in pass 'shade': GL_INVALID_OPERATION:
// glProgramUniform1i(type mismatch)"). Debug contexts are the default in debug builds and
// where LUCENT_GL_DEBUG=1 (the test suites set it).
#include <stdexcept>
#include <string_view>

namespace lucent::gl {

class GlError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Throws GlError "GL error in WHAT: <error names>[: <first debug message>]" when the
// current context reported an error since the last check (glGetError) or its debug
// callback logged one; both are cleared either way.
void check_errors(std::string_view what);

// Installs the KHR_debug message callback on the current context, synchronous so the
// message is logged on the thread whose call failed. Errors and undefined behaviour are
// kept for check_errors(); shader-compiler messages are left to ShaderError. Does
// nothing without KHR_debug. The context providers call it for debug contexts.
void install_debug_messages();

// Whether contexts are created as debug contexts unless told otherwise: true in builds
// without NDEBUG and when the environment has LUCENT_GL_DEBUG=1.
bool debug_contexts_by_default();

}  // namespace lucent::gl
