#pragma once
// What each stimulus of a protocol is before a session shows it: every knob value of its
// technique and the scene as the renderer resolves them (defaults included), its mesh and
// mesh hash, and, for a pre-rendered `--images DIR` file, the check of that file against
// DIR's stimulus-set manifest (listed, content hash and parameters as the protocol says).
#include <memory>
#include <string>
#include <vector>

#include "renderer/core/scene.h"
#include "renderer/core/stimulus_set.h"
#include "study/protocol.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

// A protocol stimulus resolved once, before a session starts: the row the database
// records and, for a stimulus rendered live here, the scene the renderer draws. Both come
// from the same knob values (full precision) and the same loaded mesh, so the recorded
// row is the scene that was drawn, not a parallel computation.
struct ResolvedProtocolStimulus {
    StimulusProvenance provenance;
    // Null for an image stimulus and for a live one shown from an --images file.
    std::shared_ptr<const Scene> scene;
};

// One entry per protocol stimulus, in protocol order. A live stimulus with a file in
// `images_dir` (<id>.png|.tif|.exr, as PrerenderedStimuli finds it) gets source "images"
// and the manifest's software and content hash; without one, "live" and this build's.
// Throws StimulusError, one line naming the file (or stimulus) and the field, for a bad
// parameter, a missing or unlisted manifest row, a changed file or a parameter, technique
// or mesh that differs from the protocol's. `catalog` supplies the knobs (tests swap it).
// A stimulus rendered live also has its scene built (at the protocol's stimulus size)
// and checked by its technique (Technique::check_scene). Each mesh is loaded once.
std::vector<ResolvedProtocolStimulus> resolve_protocol_stimuli(
    const Protocol& protocol, const std::string& images_dir,
    const SetCatalog& catalog = default_set_catalog());
// resolve_protocol_stimuli()'s database rows.
std::vector<StimulusProvenance> resolve_stimuli(
    const Protocol& protocol, const std::string& images_dir,
    const SetCatalog& catalog = default_set_catalog());

}  // namespace lucent::study
