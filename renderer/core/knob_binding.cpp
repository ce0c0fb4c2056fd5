#include "renderer/core/knob_binding.h"

#include <stdexcept>

namespace lucent {
namespace {

// A member of a type the knob's kind cannot hold is a mistake in a bind().
void require_kind(const Knob& knob, bool matches) {
    if (!matches)
        throw std::logic_error("knob '" + knob.name +
                               "' is bound to a member of another type");
}

bool is_choice(const Knob& knob) { return knob.kind == KnobKind::choice; }

}  // namespace

void KnobLister::knob(double& member, Knob knob) {
    require_kind(knob, knob.kind == KnobKind::scalar);
    knob.default_value = member;
    knobs.push_back(std::move(knob));
}

void KnobLister::knob(glm::dvec3& member, Knob knob) {
    require_kind(knob, knob.kind == KnobKind::rgb || knob.kind == KnobKind::vec3);
    knob.default_value = member;
    knobs.push_back(std::move(knob));
}

void KnobLister::knob(int& member, Knob knob) {
    require_kind(knob, knob.kind == KnobKind::integer || is_choice(knob));
    if (is_choice(knob))
        knob.default_value = std::to_string(member);
    else
        knob.default_value = member;
    knobs.push_back(std::move(knob));
}

void KnobLister::knob(bool& member, Knob knob) {
    require_kind(knob, is_choice(knob));
    knob.default_value = std::string(member ? "on" : "off");
    knobs.push_back(std::move(knob));
}

void KnobLister::knob(std::string& member, Knob knob) {
    require_kind(knob, is_choice(knob) || knob.kind == KnobKind::text);
    knob.default_value = member;
    knobs.push_back(std::move(knob));
}

void KnobLister::scene_input(Knob knob) { knobs.push_back(std::move(knob)); }

void KnobReader::knob(double& member, Knob knob) { member = values_.scalar(knob.name); }

void KnobReader::knob(glm::dvec3& member, Knob knob) { member = values_.vec3(knob.name); }

void KnobReader::knob(int& member, Knob knob) {
    member = is_choice(knob) ? std::stoi(values_.choice(knob.name))
                             : values_.integer(knob.name);
}

void KnobReader::knob(bool& member, Knob knob) {
    member = values_.choice(knob.name) == "on";
}

void KnobReader::knob(std::string& member, Knob knob) {
    member = values_.choice(knob.name);
}

}  // namespace lucent
