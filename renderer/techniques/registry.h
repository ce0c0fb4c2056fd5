#pragma once
// The one list of techniques Lucent knows, and the knobs each one accepts.
#include <string>
#include <string_view>
#include <vector>

#include "renderer/core/knobs.h"
#include "renderer/core/technique.h"

namespace lucent {

// Every technique, in registry order: the built-in ones (registry.cpp), then any
// registered by a TechniqueRegistration.
const std::vector<const Technique*>& all_techniques();

// Adds `technique` after the others while this object lives, so every layer that asks
// the registry (render, stimulus sets, protocols, the explorer, the benches) sees it: a
// technique from outside the renderer, such as one a test defines. Register before
// rendering starts (lookups are not locked); a name taken already throws
// std::logic_error.
class TechniqueRegistration {
public:
    explicit TechniqueRegistration(const Technique& technique);
    ~TechniqueRegistration();
    TechniqueRegistration(const TechniqueRegistration&) = delete;
    TechniqueRegistration& operator=(const TechniqueRegistration&) = delete;

private:
    const Technique* technique_;
};
// The technique used where none is named (`lucent render`, the benches, the explorer's
// first view): the registry's first, the thesis's empirical shader.
std::string default_technique_name();
// True when `name` is a registered technique.
bool is_technique_name(std::string_view name);
// "empirical, ward, ...": every technique's name in registry order, for messages.
std::string technique_names_listed();
// Throws KnobError "technique: 'x' is unknown (valid: empirical, ...)".
const Technique& find_technique(std::string_view name);
// scene_knobs() followed by the technique's own knobs: everything `--set` accepts.
std::vector<Knob> knobs_for(const Technique& technique);

}  // namespace lucent
