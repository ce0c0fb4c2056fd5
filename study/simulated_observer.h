#pragma once
// A simulated observer of forced choices with a known perceptual scale, so a test can
// check that the scaling recovers it (issue 30): the autopilot of `lucent run`, and the
// scripted participants of `lucent serve`'s tests, answer pairs, triads and quadruples
// with it. GL-free.
//
// The scale over a block's series is psi(v) = ((v - lo) / (hi - lo))^exponent, 0 at
// the series' low end and 1 at its high end. A pair is judged as Thurstone's Case V
// observer judges it: the stimulus with the larger psi + N(0, sigma^2) (each picture
// its own noise) looks "more"; an MLDS triad or quadruple as Maloney and Yang's
// observer: the pair whose |psi difference| is larger after adding N(0, sigma^2) to the
// difference of the two differences. So the fitted MLDS scale (psi_1 = 0, psi_p = 1) is
// psi at the series' values with the GLM's sigma = `sigma`, and the fitted Thurstone
// Case V scale is psi / (sigma * sqrt(2)) up to its reference.
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "study/protocol.h"

namespace lucent::study {

struct ObserverModel {
    double exponent = 0.5;  // the scale's shape (1: linear in the series' value)
    double sigma = 0.2;     // decision noise, in units of the scale's range
    double lapse = 0.0;     // share of choices made at random (a coin flip)

    // "EXPONENT,SIGMA" or "EXPONENT,SIGMA,LAPSE" (e.g. "0.5,0.1"); throws
    // std::invalid_argument naming the bad part.
    static ObserverModel parse(const std::string& text);
    std::string describe() const;  // "psi = x^0.5, sigma 0.1, lapse 0"

    // psi of a value on the series [lo, hi] (clamped to it).
    double scale(double value, double lo, double hi) const;
};

// The series a choice trial is judged on: the block's `series` parameter of each
// stimulus shown, and of the block's first and last stimulus (its ends). Empty
// `values` when the block names no series (the observer then chooses at random).
struct ChoiceStimuli {
    Task task = Task::pair;
    std::vector<double> values;  // one per picture shown, in screen order
    double lo = 0, hi = 1;
    // A pair's question asks for the end of the series with the lower values (the
    // block's obvious_catch puts its right answer there: e.g. a lower thickness exponent
    // looks more translucent): the observer then picks the smaller psi.
    bool more_is_lower = false;
};
ChoiceStimuli choice_stimuli(const Protocol& protocol, const std::string& block,
                             const std::vector<std::string>& shown);

// The observer's answer, 1 or 2 (PlannedTrial::shown says what each means).
int simulated_choice(const ObserverModel& observer, const ChoiceStimuli& trial,
                     std::mt19937_64& rng);

// ---- thresholds and matching (issue 31)
// ------------------------------------------------

// An observer of a difference from a standard (a staircase's 2AFC or odd-one-out trial)
// with a known psychometric function: it sees the difference `delta` with probability
// Phi((|delta| - threshold) / spread) (a cumulative Gaussian over the difference), and
// otherwise guesses (right with the task's guess rate); on a share `lapse` of the
// trials it answers at random whatever it saw. In the terms of the psychometric fit
// (analysis/psychometric): cumulative Gaussian, alpha = threshold, beta = spread,
// gamma = the guess rate, lambda = lapse * (1 - guess).
struct DetectionObserver {
    double threshold = 1.0;  // the difference seen half the time
    double spread = 0.5;     // the cumulative Gaussian's sd (> 0)
    double lapse = 0.0;      // share of trials answered at random
    // "THRESHOLD,SPREAD[,LAPSE]"; throws std::invalid_argument naming the bad part.
    static DetectionObserver parse(const std::string& text);
    // The probability of a correct answer at `delta` with guess rate `guess` (0.5 for
    // 2AFC, 1/3 for odd-one-out of three): the closed form the simulation draws from.
    double p_correct(double delta, double guess) const;
};
bool simulated_detection(const DetectionObserver& observer, double delta, double guess,
                         std::mt19937_64& rng);

// An observer matching a target's knob value with a known bias (issue 31's
// adjustment): the match it settles on is target + bias + N(0, noise^2), on the knob's
// own scale, or on its logarithm when `log_scale` (a multiplicative bias, as for a
// thickness exponent), clamped to [lo, hi].
struct MatchObserver {
    double bias = 0.0;
    double noise = 0.0;
    bool log_scale = false;
    // "BIAS,NOISE[,log]" (log: on the knob's logarithm); throws std::invalid_argument
    // naming the bad part.
    static MatchObserver parse(const std::string& text);
};
double simulated_match(const MatchObserver& observer, double target, double lo, double hi,
                       std::mt19937_64& rng);

}  // namespace lucent::study
