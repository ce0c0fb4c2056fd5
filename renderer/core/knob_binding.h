#pragma once
// One declaration per technique parameter. As a Mitsuba plugin reads each property once
// in its constructor and publishes the same members in traverse(), a technique writes
//   void bind(Params& p, KnobBinder& b) { b.knob(p.albedo, albedo_knob()); ... }
// once, and makes both its knobs() (list_knobs: each default is the member's value in a
// default Params, so a default is written once, in Params) and its params() (read_knobs:
// each member from a scene's values) from it.
#include <glm/glm.hpp>
#include <string>
#include <utility>
#include <vector>

#include "renderer/core/knobs.h"

namespace lucent {

// What bind() declares its parameters to, one call per knob in knobs() order. A knob
// passed with a member gets its default from the member; its own default_value is
// ignored.
class KnobBinder {
public:
    virtual ~KnobBinder() = default;
    virtual void knob(double& member, Knob knob) = 0;      // scalar
    virtual void knob(glm::dvec3& member, Knob knob) = 0;  // rgb or vec3
    virtual void knob(int& member, Knob knob) = 0;   // integer, or a choice such as "5"
    virtual void knob(bool& member, Knob knob) = 0;  // choice of "off" and "on"
    virtual void knob(std::string& member, Knob knob) = 0;  // choice or text
    // A knob no member holds: make_scene reads it (the density volume), not params().
    virtual void scene_input(Knob knob) = 0;

    // `member`'s knob of KnobKind::choice.
    template <class Member>
    void choice(Member& member, std::string name, std::string description,
                std::vector<std::string> choices) {
        knob(member, choice_knob(std::move(name), std::move(description), "",
                                 std::move(choices)));
    }
};

// Collects the knobs, each default from its member.
class KnobLister final : public KnobBinder {
public:
    void knob(double& member, Knob knob) override;
    void knob(glm::dvec3& member, Knob knob) override;
    void knob(int& member, Knob knob) override;
    void knob(bool& member, Knob knob) override;
    void knob(std::string& member, Knob knob) override;
    void scene_input(Knob knob) override;
    std::vector<Knob> knobs;
};

// Sets each member from resolved values.
class KnobReader final : public KnobBinder {
public:
    explicit KnobReader(const KnobValues& values) : values_(values) {}
    void knob(double& member, Knob knob) override;
    void knob(glm::dvec3& member, Knob knob) override;
    void knob(int& member, Knob knob) override;
    void knob(bool& member, Knob knob) override;
    void knob(std::string& member, Knob knob) override;
    void scene_input(Knob) override {}

private:
    const KnobValues& values_;
};

// The knobs `bind(Params&, KnobBinder&)` declares, with the defaults of a Params{}.
template <class Params, class Bind>
std::vector<Knob> list_knobs(const Bind& bind) {
    Params defaults{};
    KnobLister lister;
    bind(defaults, lister);
    return std::move(lister.knobs);
}

// A Params{} with every member `bind` declares read from `values`.
template <class Params, class Bind>
Params read_knobs(const KnobValues& values, const Bind& bind) {
    Params params{};
    KnobReader reader(values);
    bind(params, reader);
    return params;
}

}  // namespace lucent
