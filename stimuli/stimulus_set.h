#pragma once
// Stimulus sets: a TOML file naming meshes, camera, lights, material presets and a list
// of stimuli (id, technique, parameters; lists of values expand into several stimuli),
// with the resolution and image formats of the whole set. The format is documented in
// stimuli/README.md; stimuli/presets/thesis.toml is the built-in example.
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/core/knobs.h"

namespace lucent::stimuli {

// A bad config; what() is one line "FILE:LINE:COLUMN: KEY: reason".
class StimulusSetError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class ImageFormat { png, exr, tif };
std::string_view extension(ImageFormat format);  // "png", "exr", "tif"

struct Stimulus {
    std::string id;         // unique in the set; also the image file's stem
    std::string technique;  // a registered technique name
    std::string mesh_name;  // the key in [meshes]
    std::string mesh_spec;  // built-in spec ("torus_knot:60k") or absolute file path
    KnobValues parameters;  // every knob of the technique, defaults filled in
    int source_line = 0;    // line of the [[stimuli]] entry it expanded from
    // The factor series it belongs to (the entry's `series`; by default the id pattern
    // of an entry that expands into several stimuli); empty for none. The report
    // compares the levels of each series.
    std::string series;
};

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
};
SetCatalog default_catalog();

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
std::vector<std::string> preset_names();
std::optional<std::string_view> preset_text(std::string_view name);
StimulusSet load_preset(std::string_view name, const SetCatalog& catalog);

}  // namespace lucent::stimuli
