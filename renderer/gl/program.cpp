#include "renderer/gl/program.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>

namespace lucent::embedded {
std::optional<std::string_view> renderer_file(std::string_view relative_path);
}

namespace lucent::gl {
namespace {

std::string info_log(GLuint object, bool is_program) {
    GLint length = 0;
    if (is_program)
        glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
    else
        glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(length > 0 ? length : 1), '\0');
    if (is_program)
        glGetProgramInfoLog(object, length, nullptr, log.data());
    else
        glGetShaderInfoLog(object, length, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log;
}

}  // namespace

Program link_program(const std::vector<ShaderStage>& stages) {
    Program program(glCreateProgram());
    std::vector<GLuint> shaders;
    std::string names;
    for (const auto& stage : stages) {
        GLuint shader = glCreateShader(stage.type);
        const char* text = stage.source.c_str();
        glShaderSource(shader, 1, &text, nullptr);
        glCompileShader(shader);
        GLint ok = GL_FALSE;
        glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            const std::string log = info_log(shader, false);
            glDeleteShader(shader);
            for (GLuint s : shaders) glDeleteShader(s);
            throw ShaderError(stage.name + ": " + log);
        }
        glAttachShader(program.id(), shader);
        shaders.push_back(shader);
        names += (names.empty() ? "" : " + ") + stage.name;
    }
    glLinkProgram(program.id());
    for (GLuint s : shaders) {
        glDetachShader(program.id(), s);
        glDeleteShader(s);
    }
    GLint ok = GL_FALSE;
    glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
    if (!ok) throw ShaderError(names + ": link failed: " + info_log(program.id(), true));
    return program;
}

std::string shader_source(std::string_view relative_path) {
    if (const char* dir = std::getenv("LUCENT_SHADER_DIR"); dir && *dir) {
        std::ifstream file(std::filesystem::path(dir) / relative_path);
        if (file) {
            std::ostringstream text;
            text << file.rdbuf();
            return text.str();
        }
    }
    if (auto text = lucent::embedded::renderer_file(relative_path))
        return std::string(*text);
    throw ShaderError("unknown shader '" + std::string(relative_path) + "'");
}

namespace {

// Replaces each line `#include "path"` (path relative to renderer/, as shader_source
// takes) by that file's text, recursively up to a small depth, with #line directives so
// compiler errors keep pointing at the including file's own lines.
std::string expand_includes(const std::string& source, std::string_view name, int depth) {
    std::istringstream lines(source);
    std::string out, line;
    int number = 0;
    while (std::getline(lines, line)) {
        ++number;
        const std::string directive = "#include \"";
        if (line.rfind(directive, 0) == 0) {
            const std::size_t end = line.find('"', directive.size());
            if (end == std::string::npos || depth >= 8)
                throw ShaderError(std::string(name) + ":" + std::to_string(number) +
                                  ": bad #include");
            const std::string path =
                line.substr(directive.size(), end - directive.size());
            out += "#line 1\n" + expand_includes(shader_source(path), path, depth + 1);
            out += "#line " + std::to_string(number + 1) + "\n";
            continue;
        }
        out += line + "\n";
    }
    return out;
}

}  // namespace

ShaderStage shader_stage(GLenum type, std::string_view relative_path,
                         const std::vector<std::string>& defines) {
    std::string source = shader_source(relative_path);
    if (source.find("#include \"") != std::string::npos)
        source = expand_includes(source, relative_path, 0);
    if (!defines.empty()) {
        std::string block;
        for (const auto& define : defines) block += "#define " + define + "\n";
        // Insert after the #version line (which must stay first) and reset line numbers
        // so compiler errors still point at the file's own lines.
        const size_t eol = source.find('\n');
        const size_t at = eol == std::string::npos ? source.size() : eol + 1;
        source.insert(at, block + "#line 2\n");
    }
    return ShaderStage{type, std::string(relative_path), std::move(source)};
}

namespace {

// `source` with // and /* */ comments replaced by a space.
std::string without_comments(std::string_view source) {
    std::string out;
    for (std::size_t i = 0; i < source.size();) {
        if (source.compare(i, 2, "//") == 0) {
            i = source.find('\n', i);
            if (i == std::string_view::npos) break;
        } else if (source.compare(i, 2, "/*") == 0) {
            const std::size_t end = source.find("*/", i + 2);
            if (end == std::string_view::npos) break;
            out += ' ';
            i = end + 2;
        } else {
            out += source[i++];
        }
    }
    return out;
}

}  // namespace

std::set<std::string> declared_uniforms(std::string_view source) {
    static const std::regex declaration(R"(\buniform\b([^;{]*)(\{[^}]*\}[^;]*)?;)");
    static const std::regex identifier(R"([A-Za-z_][A-Za-z0-9_]*)");
    std::set<std::string> names;
    const std::string text = without_comments(source);
    for (std::sregex_iterator it(text.begin(), text.end(), declaration), end; it != end;
         ++it) {
        const std::string body = (*it)[0].str();
        for (std::sregex_iterator id(body.begin(), body.end(), identifier); id != end;
             ++id)
            names.insert((*id)[0].str());
    }
    return names;
}

std::set<int> declared_input_locations(std::string_view source) {
    static const std::regex declaration(
        R"(\blayout\s*\(\s*location\s*=\s*([0-9]+)\s*\)\s*in\b)");
    std::set<int> locations;
    const std::string text = without_comments(source);
    for (std::sregex_iterator it(text.begin(), text.end(), declaration), end; it != end;
         ++it)
        locations.insert(std::stoi((*it)[1].str()));
    return locations;
}

}  // namespace lucent::gl
