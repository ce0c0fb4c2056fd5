#pragma once
// The block keys more than one trial kind reads, read one way.
#include <string>

#include "renderer/core/knobs.h"
#include "study/protocol.h"

namespace lucent::study {

class TableReader;

// Fails at `key` unless the protocol has a stimulus `id`.
void check_stimulus_ref(const Protocol& p, TableReader& r, const std::string& key,
                        const std::string& id);
// What every block but a rating block has: its own question, answered by one
// response; its stimuli distinct and free of whitespace (trials.shown holds them
// space-separated).
void read_block_question(const Protocol& p, TableReader& r, Block& b);
// How a choice's `pictures` are shown and what its answers are called: one answer per
// picture, or (answers_are_pairs) two, the first pair and the second.
void read_presentation(TableReader& r, Block& b, int pictures, bool answers_are_pairs);
// The scalar knob `b.knob` of a live stimulus's technique; fails at `key` otherwise.
Knob block_knob(const Protocol& p, TableReader& r, const Block& b,
                const std::string& stimulus, const std::string& key);
// A live stimulus's value of a scalar knob: its parameter, else the knob's default.
double knob_value_of(const Protocol& p, const std::string& stimulus, const Knob& knob);

}  // namespace lucent::study
