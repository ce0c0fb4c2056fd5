#pragma once
// What each stimulus of a protocol is before a session shows it: every knob value of its
// technique and the scene as the renderer resolves them (defaults included), its mesh and
// mesh hash, and, for a pre-rendered `--images DIR` file, the check of that file against
// DIR's stimulus-set manifest (listed, content hash and parameters as the protocol says).
#include <string>
#include <vector>

#include "stimuli/stimulus_set.h"
#include "study/protocol.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

// One entry per protocol stimulus, in protocol order. A live stimulus with a file in
// `images_dir` (<id>.png|.tif|.exr, as PrerenderedStimuli finds it) gets source "images"
// and the manifest's software and content hash; without one, "live" and this build's.
// Throws StimulusError, one line naming the file (or stimulus) and the field, for a bad
// parameter, a missing or unlisted manifest row, a changed file or a parameter, technique
// or mesh that differs from the protocol's. `catalog` supplies the knobs (tests swap it).
std::vector<StimulusProvenance> resolve_stimuli(
    const Protocol& protocol, const std::string& images_dir,
    const stimuli::SetCatalog& catalog = stimuli::default_catalog());

}  // namespace lucent::study
