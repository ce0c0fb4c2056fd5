#pragma once
// The one reader of knob values written in TOML: stimulus sets (stimuli/stimulus_set.cpp)
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

}  // namespace lucent
