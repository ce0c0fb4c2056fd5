#pragma once
// The one stimulus record: what a stimulus set expands its [[stimuli]] entries into and
// what a study protocol shows (its own [[stimuli]] entries, or a set it names). Both read
// a parameter through the one TOML knob reader (knob_toml.h), so a stimulus a study takes
// from a set is the set's picture, value for value.
#include <map>
#include <string>
#include <vector>

#include "renderer/core/knobs.h"

namespace lucent {

// A scalar knob as a function of time: `from` at t = 0, `to` after half a period
// (back_and_forth) or just before the period ends (loop), repeating every period.
struct KnobMotion {
    enum class Shape { loop, back_and_forth };
    std::string knob;
    double from = 0.0;
    double to = 0.0;
    double period_s = 1.0;  // finite, > 0
    Shape shape = Shape::back_and_forth;

    // The knob's value at `t_s` seconds (any finite t, negative too), always between
    // `from` and `to`; throws std::invalid_argument for a non-finite t.
    double value_at(double t_s) const;
};

struct Stimulus {
    std::string id;         // unique in its set or protocol; a rendered image's file stem
    std::string technique;  // a registered technique; "" for a pre-rendered image
    std::string mesh;       // built-in spec ("torus_knot:30k") or absolute file path
    std::string mesh_name;  // a set's [meshes] key; a protocol's own entry: as `mesh`
    std::string image;      // a pre-rendered image's path ("" for a live stimulus)
    // The knobs the entry sets (from the set's defaults, camera, light, material, its own
    // keys and its vary list; a protocol entry's params), by name, in the form written: a
    // grey "0.6" stays one number, each number in the shortest text that reads back to
    // the same double, arrays as "a,b,c". These are the stimulus's factor levels.
    std::map<std::string, std::string> parameters;
    // The experimenter's own factors (an entry's `factors`, e.g. lighting = "front"):
    // named levels that are no knob, so no renderer reads them. A name is a parameter or
    // a factor, never both.
    std::map<std::string, std::string> factors;
    // Every knob of the technique, defaults filled: what a set renders. Empty for a
    // protocol's own entries, whose values are resolved when a session starts
    // (study/session/stimulus_provenance.h).
    KnobValues values;
    // Which columns the stimulus was designed to vary; empty means every column (every
    // parameter and own factor) is a factor. "technique" may be listed too, and
    // "series:NAME": a factor NAME whose levels are the stimuli listing it.
    std::vector<std::string> varies;
    // The set's factor series it belongs to (the entry's `series`; by default the id
    // pattern of an entry that expands into several stimuli); empty for none.
    std::string series;
    int source_line = 0;  // line of the entry it expanded from
    // Knobs that change over time, by knob (a set's [stimuli.motion]); `values` and
    // `parameters` hold their value at t = 0. Empty for a still stimulus.
    std::vector<KnobMotion> motion;

    bool live() const { return image.empty(); }
    bool moves() const { return !motion.empty(); }
    // Every named column of the stimulus, as written: its parameters and its own factors
    // (what a study stores with it and analyses it by).
    std::map<std::string, std::string> columns() const;
    // `values` with each moving knob at `t_s` seconds (the still's values when none
    // moves).
    KnobValues values_at(double t_s) const;
};

}  // namespace lucent
