#pragma once
// The psychometric function of a forced-choice (or yes/no) experiment, fitted by maximum
// likelihood on the binomial likelihood of the binned responses (Wichmann and Hill 2001):
//
//     psi(x) = gamma + (1 - gamma - lambda) F(x; alpha, beta)
//
// gamma, the guess rate, is fixed by the task (1/2 for 2AFC, 1/3 for the odd one out of
// three, 0 for yes/no); lambda, the lapse rate, is fixed or free in [0, max_lapse]
// (0.06, as Wichmann and Hill 2001 and psignifit suggest). F is
//   - the cumulative Gaussian: F = Phi((x - alpha) / beta), alpha its mean (F = 1/2),
//     beta its standard deviation (> 0), any real x;
//   - the Weibull: F = 1 - exp(-(x / alpha)^beta), alpha > 0 the scale (F = 1 - 1/e),
//     beta > 0 the shape; intensities must be positive (a non-positive one is refused).
// The threshold is the intensity where F reaches `threshold_level` (default 1/2, the
// midpoint of the F part: alpha for the Gaussian, alpha (ln 2)^(1/beta) for the
// Weibull), and, when `p_correct_level` is given, also where psi reaches that proportion
// correct (e.g. 0.75 for 2AFC). The slope is dpsi/dx at the threshold (proportion correct
// per unit of x, the (1 - gamma - lambda) factor included).
//
// Just-noticeable difference: when x is the difference between the comparison and the
// standard (the staircase's delta, in the knob's units), the threshold is the JND of the
// knob at that standard, at the stated performance level.
//
// Intervals: parametric bootstrap (responses simulated from the fitted psi at the tested
// intensities with the same numbers of trials, seeded mt19937_64, each sample refitted),
// percentile intervals (R's quantile type 7). Each resample follows the point estimate's
// rules: a resample whose threshold lies below the smallest intensity tested counts as
// "below", above the largest as "above", and its value is not used, only its side (the
// fit's search stops somewhere out there, at no meaningful value). A percentile that
// reaches such a resample is withheld and said as "< smallest" or "> largest": with n
// resamples that happens when more than (n - 1) (1 - level) / 2 of them lie on that side
// (more than 2.5% of a 95% interval's). Likewise a resample whose slope is not
// identified counts as steeper than any measured (a jump between two intensities) or,
// with its threshold outside the range, as unknown on either side.
//
// A slope that is not identified (no tested intensity on the rising part of F: the
// responses jump between two neighbouring intensities and the likelihood only grows as
// the function steepens) leaves the threshold anywhere between those two intensities:
// it is reported as "between a and b", with no value and no interval.
//
// Hard cases are never a NaN or an infinity: the values are left empty and the `notes`
// say why in words (no trials, one intensity only, every response correct, below
// chance, no change with intensity, a threshold outside the tested range or between two
// intensities, a lapse rate or slope at its bound, an interval end withheld).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lucent::analysis {

enum class PsychometricFamily { cumulative_gaussian, weibull };

// Guess rates of the usual tasks.
inline constexpr double kGuessTwoAfc = 0.5;
inline constexpr double kGuessOddOneOutOfThree = 1.0 / 3.0;
inline constexpr double kGuessYesNo = 0.0;

struct PsychometricTrial {
    double x = 0.0;  // intensity (or delta from the standard)
    bool correct = false;
};

struct PsychometricBin {
    double x = 0.0;
    int n_correct = 0;
    int n_trials = 0;
};

struct ParticipantTrial {
    std::string participant;
    double x = 0.0;
    bool correct = false;
};

struct PsychometricOptions {
    PsychometricFamily family = PsychometricFamily::cumulative_gaussian;
    double guess = kGuessTwoAfc;  // gamma, in [0, 1)
    bool free_lapse = true;       // lambda free in [0, max_lapse]; else fixed at `lapse`
    double lapse = 0.0;
    double max_lapse = 0.06;
    double threshold_level = 0.5;           // of F, in (0, 1)
    std::optional<double> p_correct_level;  // of psi, e.g. 0.75 for 2AFC
    int bootstrap = 0;                      // parametric bootstrap samples (0: none)
    std::uint64_t seed = 1;
    double level = 0.95;       // of the percentile intervals
    double test_level = 0.05;  // of the tests against chance and against a constant
};

// A threshold: a number only when the fitted threshold lies within the tested range.
enum class ThresholdStatus {
    estimated,       // `value` holds it
    below_range,     // below the smallest intensity tested (`bound`): "< bound"
    above_range,     // above the largest intensity tested (`bound`): "> bound"
    not_identified,  // no threshold: chance, below chance, one intensity, no trials
    between,  // the slope is not identified: anywhere in [between_low, between_high]
};

struct Threshold {
    ThresholdStatus status = ThresholdStatus::not_identified;
    std::optional<double> value;  // the intensity (estimated only)
    std::optional<double> bound;  // the tested range's end (below_range, above_range)
    // The two neighbouring intensities tested that the responses jump between (between).
    std::optional<double> between_low, between_high;
    std::optional<double> slope;  // dpsi/dx there (estimated, slope identified)
    // Bootstrap interval of the value (estimated only). Each end's status: estimated (the
    // number in ci_low / ci_high), below_range or above_range (withheld: more resamples
    // than the interval leaves out on that side put the threshold beyond the tested
    // range; that end is only "< smallest intensity" or "> largest"), not_identified (no
    // interval).
    std::optional<double> ci_low, ci_high;
    ThresholdStatus ci_low_status = ThresholdStatus::not_identified;
    ThresholdStatus ci_high_status = ThresholdStatus::not_identified;
    int bootstrap_below = 0, bootstrap_above = 0;  // resamples outside the tested range
    std::string ci_text;  // "0.31 .. 0.45", "< 0.05 .. 0.25", "0.1 .. > 0.6" or ""
    // Bootstrap interval of the slope; an end is empty (with a note) when it reaches the
    // resamples whose slope is not identified.
    std::optional<double> slope_ci_low, slope_ci_high;
    std::string
        text;  // "0.4610", "< 0.1", "> 0.8", "between 0.3 and 0.4", "not identified"
};

struct PsychometricFit {
    PsychometricFamily family = PsychometricFamily::cumulative_gaussian;
    double guess = 0.0;
    std::vector<PsychometricBin> bins;  // by intensity, bins without trials left out
    int trials = 0, correct = 0;
    bool fitted = false;  // the parameters below hold a maximum-likelihood fit
    std::optional<double> alpha, beta, lapse;
    bool lapse_free = false;
    int parameters = 0;                    // free parameters
    std::optional<double> log_likelihood;  // binomial, with log choose(n, k) (R's dbinom)
    // Deviance against the saturated model of the bins, its df (bins - parameters) and
    // the chi-squared p (asymptotic; empty when df < 1); bootstrap p when bootstrapped
    // (the share of samples whose deviance is at least the observed one).
    std::optional<double> deviance, deviance_p, deviance_p_bootstrap;
    int deviance_df = 0;
    // The likelihood-ratio test against a constant psi (the observed proportion
    // correct): chi-squared with parameters - 1 df. Not significant: no threshold.
    std::optional<double> constant_chi2, constant_p;
    int constant_df = 0;
    Threshold threshold;                   // at F = threshold_level
    std::optional<Threshold> threshold_p;  // at psi = p_correct_level
    double threshold_level = 0.5;
    std::optional<double> p_correct_level;
    int bootstrap_samples = 0;  // refitted samples used for the intervals
    bool converged = false;
    std::vector<std::string> notes;  // hard cases in words
};

struct ParticipantFits {
    PsychometricFit pooled;
    std::vector<std::pair<std::string, PsychometricFit>>
        participants;  // first seen first
};

// Trials to bins, one per distinct intensity, by increasing intensity. Throws InputError
// (analysis/data/long_table.h) naming the trial of a non-finite intensity.
std::vector<PsychometricBin> bin_trials(const std::vector<PsychometricTrial>& trials);

// Throws InputError, one line naming the bin (or trial) and value, on a non-finite
// intensity, negative counts or more correct than trials, a non-positive intensity for
// the Weibull, or options out of range.
PsychometricFit fit_psychometric(const std::vector<PsychometricBin>& bins,
                                 const PsychometricOptions& options = {});
PsychometricFit fit_psychometric(const std::vector<PsychometricTrial>& trials,
                                 const PsychometricOptions& options = {});

// Each participant, and all trials pooled.
ParticipantFits fit_psychometric_participants(const std::vector<ParticipantTrial>& trials,
                                              const PsychometricOptions& options = {});

// F and psi of a fit's family and parameters.
double psychometric_f(PsychometricFamily family, double x, double alpha, double beta);
double psychometric_psi(const PsychometricFit& fit, double x);

}  // namespace lucent::analysis
