#pragma once
// "Add to stimulus set": appends the explorer's current parameters as one [[stimuli]]
// entry to a stimulus-set config (renderer/core/stimulus_set.h), keeping the file's text
// and comments. The text is appended (plus one line under [meshes] when the mesh is new),
// then the whole file is parsed again with the stimulus-set loader; on any error the
// original file is restored. GL-free.
#include <filesystem>
#include <string>

#include "renderer/core/knobs.h"

namespace lucent::explorer {

struct StimulusEntry {
    std::string id = "explore";  // made unique in the set by a _2, _3, ... suffix
    std::string technique;
    std::string mesh;   // built-in spec or file path
    KnobValues values;  // every knob of the technique
    int width = 512;    // resolution written when the file is created
    int height = 512;
};

// Appends `entry` to `config` (created when missing); returns the id written. Throws
// StimulusSetError (the existing file or the result does not parse; the file is
// left as it was) or std::runtime_error (I/O).
std::string append_stimulus(const std::filesystem::path& config,
                            const StimulusEntry& entry);

// The [[stimuli]] table text for `entry` under `id` and mesh key `mesh_key`.
std::string stimulus_table_text(const StimulusEntry& entry, const std::string& id,
                                const std::string& mesh_key);

}  // namespace lucent::explorer
