#pragma once
// The one reader of knob values written in TOML: stimulus sets (core/stimulus_set.cpp)
// and study protocols (study/protocol.cpp) both read a parameter through it, so a value
// means the same, at full precision, wherever it is written.
#include <toml++/toml.h>

#include "renderer/core/knobs.h"

namespace lucent {

// One TOML value for `knob`, validated (type, then range): a number for a scalar, an
// integer for an integer, a number (grey), [r, g, b] or "r,g,b" for rgb, [x, y, z] or
// "x,y,z" for a vector, a string for text, a string or an integer for a choice. Numbers
// keep every bit of the double TOML parsed. Throws KnobError whose message is the reason
// alone, without the knob's name, for the caller to place at the node's file:line.
KnobValue read_knob_value(const Knob& knob, const toml::node& node);

// A TOML parameter value that cannot be kept as text; `node` is the offending value (an
// array's element where it is one), for the caller to place at its file:line.
class ParameterTextError : public KnobError {
public:
    ParameterTextError(const toml::node& where, const std::string& reason)
        : KnobError(reason), node(&where) {}
    const toml::node* node;
};

// A parameter's text as a stimulus keeps it (Stimulus::parameters: its factor level, as
// the database stores it): as written, numbers in the shortest form that reads back to
// the same double ("25" for 25.0), arrays as "a,b,c", strings as they are, booleans
// "true"/"false". A grey "0.6" stays one number. Throws ParameterTextError for a
// non-finite number or a value of another type.
std::string parameter_text(const toml::node& node);

}  // namespace lucent
