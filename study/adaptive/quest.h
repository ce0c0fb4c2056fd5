#pragma once
// QUEST (Watson and Pelli 1983) equal to PsychoPy's QuestHandler (psychopy/data/
// staircase.py over Andrew Straw's psychopy/contrib/quest.py, a port of Denis Pelli's
// Psychtoolbox code): a Gaussian prior on the threshold over a grid, the Weibull
// psychometric function
//   p(x) = delta*gamma + (1 - delta) * (1 - (1 - gamma) * exp(-10^(beta * (x + eps))))
// with eps (epsilon()) placing pThreshold at the threshold, the posterior updated by
// each answer, and the next intensity its quantile, mean or mode. GL-free.
//
// PsychoPy's arithmetic is kept so the values agree to the printed digits: the grid
// holds dim + 1 points x = i * grain, i = -dim/2..dim/2, dim = 2 * ceil(range / grain /
// 2) (500 without a range), centred on startVal; an intensity falls on the grid
// point round((intensity - startVal) / grain) with Python's round (half to even);
// sums are numpy's pairwise sums, interpolation numpy's interp.
//
// Where this differs from PsychoPy (each a case PsychoPy cannot run): gamma above
// pThreshold is refused (PsychoPy warns and sets 0.5); with delta = 0 an answer the
// model makes impossible everywhere leaves the posterior as it was (PsychoPy's pdf
// becomes all zero and it raises); the posterior is rescaled by a power of two
// before it would underflow (exact, so no value changes); ties of the mode take the
// lowest intensity.
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "study/adaptive/staircase.h"

namespace lucent::study::adaptive {

enum class QuestMethod { quantile, mean, mode };
QuestMethod parse_quest_method(std::string_view text);  // throws invalid_argument
std::string_view to_string(QuestMethod method);

struct QuestSettings {
    double start = 0;     // startVal: the prior's mean, and the first trial
    double start_sd = 1;  // startValSd: the prior's standard deviation
    double p_threshold = 0.82;
    std::optional<int> n_trials;          // stop after this many trials
    std::optional<double> stop_interval;  // or when the 5-95 % interval is narrower
    QuestMethod method = QuestMethod::quantile;
    double beta = 3.5;    // steepness of the Weibull
    double delta = 0.01;  // lapse: share of blind answers
    double gamma = 0.5;   // share of answers 1 at intensity -infinity (guess rate)
    double grain = 0.01;  // grid step
    std::optional<double> range;  // grid width, centred on start (none: 500 grains)
    std::optional<double> min_value, max_value;  // proposals are held inside
};

class Quest final : public AdaptiveProcedure {
public:
    // Throws std::invalid_argument (one line naming the parameter) for non-finite
    // values, start_sd, grain or range not positive, p_threshold, gamma or delta
    // outside [0, 1), gamma above p_threshold, no stop rule, minVal above maxVal, and a
    // psychometric function whose range omits p_threshold.
    explicit Quest(QuestSettings settings);

    Proposal next() override;
    void add_response(bool correct, std::optional<double> shown = std::nullopt) override;
    bool finished() const override { return finished_; }
    const std::vector<double>& intensities() const override { return intensities_; }
    const std::vector<int>& responses() const override { return responses_; }
    bool hit_range() const override;

    const QuestSettings& settings() const { return settings_; }
    Proposal upcoming() const { return {next_intensity_, next_clamped_}; }
    const std::vector<bool>& clamped_trials() const { return clamped_; }

    // The posterior's statistics, in intensity units (PsychoPy's mean(), mode(),
    // quantile(p), sd(), confInterval()). quantile() without p takes QUEST's most
    // informative order (quantile_order()).
    double mean() const;
    double mode() const;
    double quantile(std::optional<double> p = std::nullopt) const;
    double sd() const;
    std::pair<double, double> conf_interval() const;  // 5 % and 95 % quantiles
    double conf_interval_width() const;

    double epsilon() const { return x_threshold_; }  // PsychoPy's q.epsilon
    double quantile_order() const { return quantile_order_; }
    // The grid's offsets from start (x) and the unnormalised posterior on it.
    const std::vector<double>& grid() const { return x_; }
    const std::vector<double>& posterior() const { return pdf_; }

private:
    void update(double intensity, bool correct);
    void choose_next();

    QuestSettings settings_;
    long dim_ = 500;
    std::vector<double> x_;    // grid offsets i * grain
    std::vector<double> pdf_;  // posterior, unnormalised
    std::vector<double> p2_;   // psychometric function on the doubled grid
    double x_threshold_ = 0;
    double quantile_order_ = 0.5;
    double next_intensity_ = 0;
    bool next_clamped_ = false;
    bool pending_ = false;
    bool finished_ = false;
    std::vector<double> intensities_;
    std::vector<int> responses_;
    std::vector<bool> clamped_;
};

}  // namespace lucent::study::adaptive
