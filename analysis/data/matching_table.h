#pragma once
// The rows every matching and threshold analysis starts from (issue 31): one per
// answered adjust trial (the value the participant confirmed) and one per answered
// staircase trial (the delta shown and whether the choice was right), with the stored
// protocol that says what each block's knob, match, range and procedures were. They come
// out of a study's observations (common/observation_table.h, read by
// study/observations.h), which have left practice, withdrawn and unselected sessions and
// excluded participants out already. Part of lucent_matching (it replays the study's
// adaptive procedures, study/adaptive).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/observation_table.h"
#include "study/protocol.h"

namespace lucent::analysis {

// An adjust trial: the match's knob turned from `start_value` to `final_value`.
struct MatchRow {
    std::string participant;
    std::string session;  // session UUID
    int trial = 0;        // position in the session
    std::string block;
    std::string target;  // the target stimulus shown beside the match
    std::string match;   // the block's live match stimulus
    std::string knob;    // the block's knob
    std::optional<double> start_value;
    double final_value = 0;
    double rt_ms = 0;     // from onset to the confirmation
    int adjustments = 0;  // changes of the knob on the way
};

// A staircase trial: the standard against standard + `intensity` (the delta).
struct StaircaseRow {
    std::string participant;
    std::string session;
    int trial = 0;  // position in the session (the procedures' order)
    std::string block;
    std::string standard;   // the standard stimulus
    std::string staircase;  // its procedure, "<standard>/<procedure id>"
    double intensity = 0;   // the delta shown
    int expected = 0;       // the comparison's place: the right answer
    int choice = 0;         // the place chosen
    bool correct = false;   // choice == expected
    double rt_ms = 0;
};

struct MatchingTable {
    std::vector<MatchRow> matches;
    std::vector<StaircaseRow> staircases;  // by participant, session, position
    // The stored protocol (its blocks' knobs, ranges, procedures; its stimuli's
    // parameters); empty when the database holds none that parses.
    std::optional<study::Protocol> protocol;
    std::vector<std::string> excluded_participants;  // "P3 (2 catch trials failed)"
    // The sessions taken and left out, in one line, as the ratings' reader says it.
    std::string sessions_note;
};

// The adjust trials with a confirmed value and the staircase trials with a delta and a
// right answer, in the observations' order; `protocol` names each block's knob and match.
MatchingTable matching_of(const common::ObservationTable& observations,
                          std::optional<study::Protocol> protocol);

}  // namespace lucent::analysis
