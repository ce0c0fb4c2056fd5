#pragma once
// Stimulus sets: a TOML file naming meshes, camera, lights, material presets and a list
// of stimuli (id, technique, parameters; lists of values expand into several stimuli),
// with the resolution and image formats of the whole set. The format is documented in
// stimuli/README.md; renderer/core/presets/thesis.toml is the built-in example. It sits
// in the renderer's core, below stimuli/ and study/, because both read it: `lucent
// render` renders a set and a protocol may take its stimuli from one.
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/core/knobs.h"
#include "renderer/core/stimulus.h"

namespace lucent {

// A bad config; what() is one line "FILE:LINE:COLUMN: KEY: reason".
class StimulusSetError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class ImageFormat { png, exr, tif };
std::string_view image_extension(ImageFormat format);  // "png", "exr", "tif"

struct StimulusSet {
    std::string name;
    std::string source;  // the config file, or "preset:NAME"
    int width = 512;
    int height = 512;
    std::vector<ImageFormat> formats{ImageFormat::png};
    std::vector<Stimulus> stimuli;
};

// What the loader may know about techniques and meshes; the default reads the technique
// registry and the built-in mesh list, tests pass small fakes.
struct SetCatalog {
    // The knobs of a technique, or nullopt for an unknown name.
    std::function<std::optional<std::vector<Knob>>(std::string_view)> knobs_of;
    std::vector<std::string> technique_names;  // for error messages, in order
    std::vector<std::string> builtin_meshes;   // "sphere", "torus_knot", ...
    // Whether the program shows moving stimuli ([stimuli.motion]). No renderer or runner
    // draws them yet, so every program refuses them rather than show a still in their
    // place; the record and its parse are tested with this set.
    bool draws_motion = false;
};
// The technique registry and the built-in meshes (renderer/techniques/set_catalog.cpp).
SetCatalog default_set_catalog();

// Parses `toml_text`; `source_name` is used in messages and `base_dir` resolves relative
// mesh paths. Throws StimulusSetError; reads no file other than checking mesh paths
// exist.
StimulusSet parse_stimulus_set(std::string_view toml_text, const std::string& source_name,
                               const std::filesystem::path& base_dir,
                               const SetCatalog& catalog);
// Reads and parses a config file (errors name it).
StimulusSet load_stimulus_set(const std::filesystem::path& file,
                              const SetCatalog& catalog);

// Built-in sets embedded in the binary ("thesis"); text is the TOML file as committed.
std::vector<std::string> set_preset_names();
std::optional<std::string_view> set_preset_text(std::string_view name);
StimulusSet load_set_preset(std::string_view name, const SetCatalog& catalog);

}  // namespace lucent
