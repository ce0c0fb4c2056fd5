#pragma once
// Asymmetric matching (issue 31, section 1): per condition (an adjust block and one of
// its targets) the participants' confirmed match values, against the target's own value
// of the knob where it has one.
//
// - Mean, SD, n and the t interval of the mean over the condition's trials (every trial
//   an observation); each participant's mean, and, with two or more participants, the
//   t interval over the participant means (the interval to quote when trials of one
//   person are not independent). A "log" block's on log10: geometric means, intervals
//   back-transformed, SDs in log10 units.
// - The target's value: its `knob` parameter when the target is a live stimulus of the
//   match's technique that states it; else none ("no physical value": a picture, or
//   another technique whose knob is not the match's).
// - Bias = mean match - target value, its interval the mean's shifted by the target.
// - Constancy index, where the target and the match differ in exactly one scene factor
//   (differing_factors):
//       CI = 1 - |mean match - reference| / max(reference - lo, hi - reference)
//   on the knob's scale (its logarithm for a "log" block), lo..hi the block's range. The
//   reference is the target's own value, or, when it has none (another technique), the
//   mean match of the same target in a block whose match shares every scene factor with
//   it (the same-scene match: what the target's material is on the knob). 1: the match
//   across the factor equals the reference (full constancy); 0: it is as far from it as
//   the range allows. A simple, bounded form of the Brunswik/Thouless ratio that needs
//   no model of the "no constancy" match (a picture-matching observer's setting, which
//   the study does not measure).
// Never NaN or Inf: what is undefined is empty, and `notes` say why in words.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/data/matching_table.h"

namespace lucent::analysis {

struct ParticipantMatch {
    std::string participant;
    int n = 0;
    double mean = 0;
};

struct ConditionMatch {
    std::string block, target, match, knob;
    bool log_scale = false;  // the block's scale is "log"
    double range_min = 0, range_max = 0;
    int n = 0;  // trials
    // Of the final values over the trials. A log block's (on_log10): the geometric mean,
    // its interval from log10's t interval back-transformed, the SD in log10 units.
    std::optional<double> mean, sd, ci_low, ci_high;
    bool on_log10 = false;
    std::vector<ParticipantMatch> participants;  // first seen first
    // Over the participant means (two or more participants).
    std::optional<double> participant_mean, participant_sd, participant_ci_low,
        participant_ci_high;
    std::optional<double> target_value;
    std::optional<double> bias, bias_ci_low, bias_ci_high;
    std::optional<double> constancy;
    std::string constancy_factor;  // the scene factor the target and match differ in
    std::optional<double> constancy_reference;  // what the mean match is compared with
    // The scene factors in which the target and the match differ (differing_factors),
    // when both are live stimuli of the protocol.
    std::vector<std::string> factors;
    bool factors_known = false, picture_target = false;
    std::string no_value_reason;  // why there is no target value
    std::string constancy_text;   // the index, or why there is none, in words
    bool all_at_range_end = false;
    std::vector<std::string> notes;
};

struct MatchingOptions {
    double level = 0.95;  // of the t intervals
};

// One ConditionMatch per (block, target) in the rows' order of first appearance.
// `protocol` (the stored one; may be null) gives the blocks' ranges and scales and the
// stimuli's parameters; without it there are no target values or indices.
std::vector<ConditionMatch> analyse_matches(const std::vector<MatchRow>& rows,
                                            const study::Protocol* protocol,
                                            const MatchingOptions& options = {});

// The mean, SD and t interval of `values` (SD and interval need two values).
struct MeanInterval {
    std::optional<double> mean, sd, low, high;
};
MeanInterval mean_interval(const std::vector<double>& values, double level = 0.95);

// The index above, from its parts (log: on log10 of each). Empty when the range leaves
// no room on either side of the target or a value is not positive on a log scale.
std::optional<double> constancy_index(double mean_match, double target, double lo,
                                      double hi, bool log_scale = false);

// A live stimulus's value of a scalar knob: its parameter, else its technique's default
// (what the renderer drew); empty for a picture, an unknown stimulus or technique.
std::optional<double> knob_value(const study::Protocol& protocol,
                                 const std::string& stimulus, const std::string& knob);

// The scene factors in which two live stimuli differ, the knob aside: "mesh", and each
// parameter whose text differs (or that one of them lacks); across techniques only the
// scene's knobs (light, camera, background: renderer/core/common_knobs.h), since each
// technique's own knobs describe the material being matched.
std::vector<std::string> differing_factors(const Stimulus& a, const Stimulus& b,
                                           const std::string& knob);

}  // namespace lucent::analysis
