#pragma once
// Thresholds from staircase blocks (issue 31, section 2).
//
// Per participant x block x standard, every trial of that standard's procedures (all the
// interleaved staircases and QUESTs pooled) is fitted by maximum likelihood
// (analysis/psychometric: cumulative Gaussian by default, or Weibull) with the task's
// guess rate (1/2 for a pair, 1/3 for an odd one out) and the lapse rate free within
// [0, 0.06]. The just-noticeable difference (JND) is the delta where the fitted psi
// reaches (1 + guess) / 2, halfway between chance and perfect: 75 % correct for a pair,
// 66.7 % for an odd one out (F = 1/2 when the lapse rate is 0; a little above with one),
// with a parametric-bootstrap percentile interval. The Weber fraction is JND / the
// standard's value of the knob, where that is positive.
//
// Each procedure's own estimate is the cross-check: a transformed up/down staircase's
// mean of its last reversals (up to `last_reversals`, at least two), a QUEST's
// posterior quantile (the quantile QUEST itself proposes from), each replayed from the
// stored deltas and answers with study/adaptive's engines.
//
// Hard cases in words: at chance (no threshold), every answer correct (the JND is below
// the smallest delta shown), answers that jump from chance to correct between two
// neighbouring deltas (the slope is not identified: the JND is "between a and b", with
// no interval), bootstrap resamples beyond the deltas shown (more than the interval
// leaves out on a side: that end is only "< smallest delta" or "> largest"), a procedure
// held at the largest delta the block allows (reached at least twice: the knob's range
// limits the staircase; the threshold may lie beyond it). A Weber fraction is never
// negative: none where the JND or an end of its interval is not positive.
//
// Right on every trial with a non-zero delta: a participant who answers every one of at
// least kAllCorrectFlagTrials (20) trials with a non-zero delta correctly is flagged (as
// a script that reads the answer would be). A staircase keeps its trials near the
// threshold, where a genuine observer is right about 80% of the time (1-up/3-down
// converges at 79.4%, QUEST at its p_threshold): such an observer is right on 20 of them
// in a row with probability 0.8^20 = 0.012; one who is right 90% of the time even
// there, 0.9^20 = 0.12. The flag is a prompt to look, not a verdict: an observer whose
// JND is below the smallest delta shown is right on them too. Trials at a delta of 0 are
// left out of the count (there the two are the same and the answer is a guess).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/matching_table.h"
#include "analysis/psychometric/psychometric.h"

namespace lucent::analysis {

inline constexpr int kAllCorrectFlagTrials = 20;

struct ThresholdOptions {
    PsychometricFamily family = PsychometricFamily::cumulative_gaussian;
    int bootstrap = 200;
    std::uint64_t seed = 1;
    int last_reversals = 6;  // up/down: the estimate averages at most this many
};

// One procedure's trials in one session, in order.
struct StaircaseTrack {
    std::string participant, session, block, standard, label;
    std::string procedure;  // its id in the block
    std::string method;     // "updown" or "quest" ("" when not in the protocol)
    std::vector<double> intensity;
    std::vector<bool> correct;
    std::vector<bool> reversal;  // per trial (up/down only)
    std::optional<double> estimate;
    std::string estimate_text;  // the estimate with how it was made, or why none
    double max_delta = 0, min_delta = 0;
    int at_max = 0, at_min = 0;  // trials at the block's largest / smallest delta
    bool held_at_max = false;    // at_max >= 2
    std::vector<std::string> notes;
};

struct StandardThreshold {
    std::string participant, block, standard, knob;
    std::optional<double> standard_value;  // the standard's value of the knob
    double guess = 0.5;
    double p_correct = 0.75;  // the JND's proportion correct, (1 + guess) / 2
    PsychometricFit fit;
    // The JND and its interval's ends, where they are numbers within the deltas shown.
    std::optional<double> jnd, jnd_low, jnd_high;
    // The slope not identified: the two deltas the answers jump between.
    std::optional<double> jnd_between_low, jnd_between_high;
    std::optional<double> weber, weber_low, weber_high;  // positive only
    std::string jnd_text;     // "0.123", "< 0.05", "> 3", "between 0.1 and 0.15", ...
    std::string jnd_ci_text;  // "0.1 .. 0.2", "< 0.05 .. 0.25", "0.1 .. > 3", or ""
    std::string weber_text, weber_ci_text;  // the same for the Weber fraction, or ""
    // Trials with a non-zero delta, and how many of them were answered correctly; flagged
    // when all of at least kAllCorrectFlagTrials were.
    int nonzero_trials = 0, nonzero_correct = 0;
    bool all_nonzero_correct = false;
    std::vector<std::size_t> tracks;  // indices into ThresholdAnalysis::tracks
    std::vector<std::string> notes;   // hard cases in words (the fit's notes included)
};

struct ThresholdAnalysis {
    std::vector<StandardThreshold> thresholds;  // first seen first
    std::vector<StaircaseTrack> tracks;
};

// `protocol` (the stored one; may be null) gives the blocks' trial kinds, procedures,
// delta bounds and knobs. Without it the guess rate is 1/2 and no procedure is replayed.
ThresholdAnalysis analyse_thresholds(const std::vector<StaircaseRow>& rows,
                                     const study::Protocol* protocol,
                                     const ThresholdOptions& options = {});

// The up/down estimate of a track: the mean of its last `last` reversal intensities
// (at least two reversals).
std::optional<double> reversal_estimate(const std::vector<double>& reversal_intensities,
                                        int last);

}  // namespace lucent::analysis
