#pragma once
// Shader programs: compile and link GLSL with errors that name the source and line, and
// look shader text up by its path relative to renderer/ (embedded at build time; read
// from disk instead when LUCENT_SHADER_DIR is set, for reloading in developer mode).
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/gl/objects.h"

namespace lucent::gl {

class ShaderError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ShaderStage {
    GLenum type;       // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, ...
    std::string name;  // shown in errors, e.g. "techniques/empirical/shaders/shade.frag"
    std::string source;  // full GLSL text, #version line included
};

// Compiles and links; throws ShaderError with "<name>: <driver log>" on failure.
Program link_program(const std::vector<ShaderStage>& stages);

// Shader text by path relative to renderer/, e.g. "gl/shaders/fullscreen.vert".
// With LUCENT_SHADER_DIR set the file is read from that directory first.
// Throws ShaderError when the path is unknown.
std::string shader_source(std::string_view relative_path);

// Stage from shader_source(); `defines` are inserted after the #version line as
// "#define NAME" or "#define NAME VALUE", so variants are compiled, not branched.
ShaderStage shader_stage(GLenum type, std::string_view relative_path,
                         const std::vector<std::string>& defines = {});

// What GLSL source declares, read from its text with comments stripped and before the
// preprocessor, so every variant's declarations count: a name the linked program has no
// location for but the source declares is inactive in this variant (compiled out by a
// define or optimised away), not misspelt.
// Names in `uniform` declarations ("uniform vec3 a, b[2];" gives a and b).
std::set<std::string> declared_uniforms(std::string_view source);
// Locations of `layout(location = N) in` declarations (vertex inputs).
std::set<int> declared_input_locations(std::string_view source);

}  // namespace lucent::gl
