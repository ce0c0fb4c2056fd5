// Built-in stimulus sets: the TOML files under renderer/core/presets/, embedded at build
// time.
#include <optional>
#include <string>
#include <string_view>

#include "renderer/core/stimulus_set.h"

namespace lucent::embedded {
std::optional<std::string_view> set_preset_file(std::string_view relative_path);
}

namespace lucent {

std::vector<std::string> set_preset_names() {
    return {"thesis",  "heterogeneous", "fabrics", "physical",
            "scaling", "matching",      "jnd"};
}

std::optional<std::string_view> set_preset_text(std::string_view name) {
    for (const auto& known : set_preset_names())
        if (known == name)
            return embedded::set_preset_file("presets/" + std::string(name) + ".toml");
    return std::nullopt;
}

StimulusSet load_set_preset(std::string_view name, const SetCatalog& catalog) {
    const auto text = set_preset_text(name);
    if (!text) {
        std::string valid;
        for (const auto& known : set_preset_names())
            valid += (valid.empty() ? "" : ", ") + known;
        throw StimulusSetError("--preset: unknown preset '" + std::string(name) +
                               "' (valid: " + valid + ")");
    }
    // Presets name built-in meshes only, so the base directory is never used.
    auto set = parse_stimulus_set(*text, "preset:" + std::string(name), ".", catalog);
    return set;
}

}  // namespace lucent
