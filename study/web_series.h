#pragma once
// What `lucent serve` shows of the pictures the lab renders live at the participant's
// value (issue 31): an adjust block's match as a series of pictures along its knob, and
// a staircase block's comparisons as a ladder of deltas per standard. Each picture is a
// live stimulus of its own (the base stimulus with the knob set), so `lucent render
// --study` writes it and the stimulus-set manifest checks it like any other picture;
// SessionFlow moves the match over the series and shows each staircase delta as its
// nearest rung (session_flow.h: show_series). GL-free.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "study/protocol.h"

namespace lucent::study {

struct KnobSeries {
    std::string block;
    std::string stimulus;  // adjust: the match; staircase: one standard
    std::string knob;
    // Adjust: the knob's values from range_min to range_max, evenly spaced on the
    // block's scale (Block::series_steps of them, the ends exact). Staircase: the deltas
    // k * ladder_step within the procedures' [min_delta, max_delta], ascending.
    std::vector<double> steps;
    // The stimulus id of each step's picture: "<stimulus>@<knob>=<value>", or the id of
    // a protocol stimulus (or an earlier series's picture) showing the same picture, as a
    // delta of 0 shows the standard itself.
    std::vector<std::string> pictures;
};

struct WebSeries {
    std::vector<KnobSeries> series;
    // The pictures that are no protocol stimulus: live stimuli of their own (the base
    // stimulus with the knob set), each once.
    std::vector<Stimulus> added;
    // The series of an adjust block (stimulus: its match) or a staircase block's
    // standard; nullptr when there is none.
    const KnobSeries* find(std::string_view block, std::string_view stimulus) const;
};

// A live stimulus's value of a scalar knob: its parameter, else the knob's default (an
// adjust target's, a staircase standard's).
double stimulus_knob_value(const Protocol& protocol, std::string_view stimulus,
                           const std::string& knob);
// The knob values of an adjust block's series (see KnobSeries::steps).
std::vector<double> adjust_series_values(const Block& block);
// The deltas of a staircase block's ladder (see KnobSeries::steps).
std::vector<double> ladder_deltas(const Block& block);
// The index of the step nearest to `value` (the lower one on a tie); steps ascending,
// not empty.
size_t nearest_step(const std::vector<double>& steps, double value);
// The picture id of `stimulus` with `knob` at `value`.
std::string series_picture_id(std::string_view stimulus, std::string_view knob,
                              double value);

// Every adjust and staircase block's series, and the pictures they add. Throws
// ProtocolError when a new picture's id is already a protocol stimulus's, a ladder is
// too long or a numeric adjust start is no series value.
WebSeries web_series(const Protocol& protocol);
// `protocol` with series.added appended to its stimuli; its text, blocks and everything
// else unchanged.
Protocol with_series_pictures(const Protocol& protocol, const WebSeries& series);

}  // namespace lucent::study
