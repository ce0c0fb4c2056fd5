#include "stimuli/explorer/stimulus_entry.h"

#include <toml++/toml.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "common/output_file.h"
#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"

namespace lucent::explorer {
namespace {

std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path.string() + ": cannot read");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// Temporary file + rename (common/output_file.h): the config is never seen half written.
void write_text(const std::filesystem::path& path, const std::string& text) {
    common::write_file_atomically(path, true, [&](std::ostream& out) { out << text; });
}

std::string quoted(const std::string& text) {
    std::string out = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

// A knob value as TOML: numbers, [a, b, c] arrays, strings for choices.
std::string toml_value(const KnobValue& value) {
    if (std::holds_alternative<std::string>(value))
        return quoted(std::get<std::string>(value));
    std::string text = format_knob_value(value);
    if (!std::holds_alternative<glm::dvec3>(value)) return text;
    std::string array = "[";
    for (char c : text) array += c == ',' ? std::string(", ") : std::string(1, c);
    return array + "]";
}

// The key under [meshes] naming `spec`, or "" when no entry does.
std::string find_mesh_key(const toml::table& root, const std::filesystem::path& base_dir,
                          const std::string& spec) {
    const auto* meshes = root["meshes"].as_table();
    if (!meshes) return "";
    for (auto&& [key, value] : *meshes) {
        const auto* text = value.as_string();
        if (!text) continue;
        if (text->get() == spec) return std::string(key.str());
        std::error_code error;
        const std::filesystem::path a = base_dir / text->get(), b(spec);
        if (std::filesystem::exists(b, error) && std::filesystem::equivalent(a, b, error))
            return std::string(key.str());
    }
    return "";
}

// A fresh key for a mesh: letters, digits and _ from the spec.
std::string new_mesh_key(const toml::table& root, const std::string& spec) {
    std::string stem = std::filesystem::path(spec).stem().string();
    std::string key = "explore_";
    for (char c : stem) key += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    const auto* meshes = root["meshes"].as_table();
    std::string unique = key;
    for (int n = 2; meshes && meshes->contains(unique); ++n)
        unique = key + "_" + std::to_string(n);
    return unique;
}

// The offset just past the line holding the `[meshes]` header (optionally followed by a
// comment), or npos. `text` ends with a newline.
std::size_t after_meshes_header(const std::string& text) {
    for (std::size_t start = 0; start < text.size();) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        std::string_view line(text.data() + start, end - start);
        line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
        if (line.rfind("[meshes]", 0) == 0) {
            line.remove_prefix(8);
            line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
            if (line.empty() || line.front() == '#')
                return std::min(end + 1, text.size());
        }
        start = end + 1;
    }
    return std::string::npos;
}

}  // namespace

std::string stimulus_table_text(const StimulusEntry& entry, const std::string& id,
                                const std::string& mesh_key) {
    std::ostringstream out;
    out << "\n# Added by lucent explore.\n[[stimuli]]\n"
        << "id = " << quoted(id) << "\n"
        << "technique = " << quoted(entry.technique) << "\n"
        << "mesh = " << quoted(mesh_key) << "\n";
    for (const Knob& knob : knobs_for(find_technique(entry.technique)))
        out << knob.name << " = " << toml_value(entry.values.get(knob.name)) << "\n";
    return out.str();
}

std::string append_stimulus(const std::filesystem::path& config,
                            const StimulusEntry& entry) {
    const SetCatalog catalog = default_set_catalog();
    std::error_code error;
    const bool exists = std::filesystem::exists(config, error);
    std::string original, text;
    std::set<std::string> ids;
    std::string mesh_key;
    if (exists) {
        original = read_text(config);
        // The file must be a valid set before we touch it.
        for (const auto& stimulus : load_stimulus_set(config, catalog).stimuli)
            ids.insert(stimulus.id);
        const toml::table root = toml::parse(original, config.string());
        mesh_key = find_mesh_key(root, config.parent_path(), entry.mesh);
        text = original;
        if (!text.empty() && text.back() != '\n') text += '\n';
        if (mesh_key.empty()) {
            // A second mesh would make entries that rely on "the one mesh" ambiguous.
            const auto* meshes = root["meshes"].as_table();
            const auto* stimuli = root["stimuli"].as_array();
            if (meshes && meshes->size() == 1 && stimuli)
                for (const auto& node : *stimuli)
                    if (const auto* table = node.as_table();
                        table && !table->contains("mesh"))
                        throw StimulusSetError(
                            config.string() + ":" +
                            std::to_string(table->source().begin.line) +
                            ": mesh: adding mesh '" + entry.mesh +
                            "' would leave this stimulus "
                            "without one (name its mesh, or explore the config's own "
                            "mesh)");
            // A new mesh goes on the line after the [meshes] header.
            mesh_key = new_mesh_key(root, entry.mesh);
            const std::size_t at = after_meshes_header(text);
            if (at == std::string::npos)
                throw StimulusSetError(config.string() +
                                       ": meshes: no [meshes] table to add mesh '" +
                                       entry.mesh + "' to");
            text.insert(at, mesh_key + " = " + quoted(entry.mesh) +
                                "  # added by lucent explore\n");
        }
    } else {
        mesh_key = "explore_mesh";
        text =
            "# Stimulus set started by lucent explore (format: stimuli/README.md).\n"
            "name = \"explore\"\n"
            "resolution = [" +
            std::to_string(entry.width) + ", " + std::to_string(entry.height) +
            "]\nformats = [\"png\"]\n\n[meshes]\n" + mesh_key + " = " +
            quoted(entry.mesh) + "\n";
    }
    std::string id = entry.id;
    for (int n = 2; ids.count(id); ++n) id = entry.id + "_" + std::to_string(n);
    text += stimulus_table_text(entry, id, mesh_key);

    write_text(config, text);
    try {
        load_stimulus_set(config, catalog);
    } catch (...) {
        // Roll back: the file is exactly as before (or gone, when we created it).
        if (exists)
            write_text(config, original);
        else
            std::filesystem::remove(config, error);
        throw;
    }
    return id;
}

}  // namespace lucent::explorer
