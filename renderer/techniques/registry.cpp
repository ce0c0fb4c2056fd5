#include "renderer/techniques/registry.h"

#include <stdexcept>

#include "renderer/core/common_knobs.h"

namespace lucent {

// Each technique defines one accessor (ward/technique.cpp defines ward's and
// contrast_reversed's: one class, two variants); adding a technique adds one line to
// each list below.
const Technique& empirical_technique();
const Technique& ward_technique();
const Technique& contrast_reversed_technique();
const Technique& dipole_technique();
const Technique& htsm_technique();
const Technique& thick_texture_technique();
const Technique& path_technique();

namespace {

std::vector<const Technique*>& registered() {
    static std::vector<const Technique*> techniques = {
        &empirical_technique(), &ward_technique(), &contrast_reversed_technique(),
        &dipole_technique(),    &htsm_technique(), &thick_texture_technique(),
        &path_technique(),
    };
    return techniques;
}

}  // namespace

const std::vector<const Technique*>& all_techniques() { return registered(); }

TechniqueRegistration::TechniqueRegistration(const Technique& technique)
    : technique_(&technique) {
    if (is_technique_name(technique.name()))
        throw std::logic_error("technique '" + std::string(technique.name()) +
                               "' is registered already");
    registered().push_back(technique_);
}

TechniqueRegistration::~TechniqueRegistration() { std::erase(registered(), technique_); }

std::string default_technique_name() {
    return std::string(all_techniques().front()->name());
}

bool is_technique_name(std::string_view name) {
    for (const Technique* technique : all_techniques())
        if (technique->name() == name) return true;
    return false;
}

std::string technique_names_listed() {
    std::string names;
    for (const Technique* technique : all_techniques())
        names += (names.empty() ? "" : ", ") + std::string(technique->name());
    return names;
}

const Technique& find_technique(std::string_view name) {
    for (const Technique* technique : all_techniques())
        if (technique->name() == name) return *technique;
    throw KnobError("technique: '" + std::string(name) +
                    "' is unknown (valid: " + technique_names_listed() + ")");
}

std::vector<Knob> knobs_for(const Technique& technique) {
    std::vector<Knob> knobs = scene_knobs();
    const auto& own = technique.knobs();
    knobs.insert(knobs.end(), own.begin(), own.end());
    return knobs;
}

}  // namespace lucent
