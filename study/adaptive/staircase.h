#pragma once
// Adaptive choice of a trial's intensity (issue 31, section 2): transformed up/down
// staircases equal to PsychoPy's StairHandler, and interleaved procedures equal to its
// MultiStairHandler. QUEST is in study/adaptive/quest.h. GL-free; the study runner asks
// next() for each trial's intensity (a delta of a knob) and gives add_response() the
// participant's answer. tests/study/adaptive/PSYCHOPY.md lists the PsychoPy tests the
// engines reproduce.
//
// PsychoPy's rules, kept here:
// - Until the first reversal the staircase runs 1-up/1-down (apply_initial_rule); the
//   first reversal is stepped by that rule too, then n_up/n_down count runs of equal
//   answers (a run restarts after every step).
// - step_sizes[k] is used after the k-th reversal, the last one for ever after; the
//   step that follows a reversal already uses the new size.
// - Finished when at least n_trials trials AND at least n_reversals reversals were
//   run; n_reversals is at least step_sizes.size() (PsychoPy raises it, and takes
//   step_sizes.size() when none is given).
// - A step that would pass max_value (going up) or min_value (going down) stops at
//   the bound; the start value itself is not stepped.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string_view>
#include <vector>

namespace lucent::study::adaptive {

// One trial's intensity. `clamped`: the procedure wanted to go beyond min_value or
// max_value and was held at the bound ("the staircase hit the knob's range").
struct Proposal {
    double intensity = 0;
    bool clamped = false;
};

// What the study runner drives: a staircase or a QUEST. Trials alternate: next(),
// then add_response() with the answer to that trial.
class AdaptiveProcedure {
public:
    virtual ~AdaptiveProcedure() = default;
    // The next trial's intensity, recorded in intensities(). Throws std::logic_error
    // when finished() or when the previous trial has no response yet.
    virtual Proposal next() = 0;
    // The answer to the trial last proposed (true: correct / detected). `shown`: the
    // intensity really shown when it differs from the proposal (a pre-rendered ladder's
    // nearest step); it replaces the recorded intensity, as PsychoPy's
    // addResponse(result, intensity) does. Throws std::logic_error without a pending
    // trial, std::invalid_argument for a non-finite `shown`.
    virtual void add_response(bool correct,
                              std::optional<double> shown = std::nullopt) = 0;
    virtual bool finished() const = 0;
    virtual const std::vector<double>& intensities() const = 0;  // one per trial
    virtual const std::vector<int>& responses() const = 0;       // 1 correct, 0 wrong
    // Some proposal was held at min_value or max_value.
    virtual bool hit_range() const = 0;
};

enum class StepType { lin, log, db };
// "lin", "log" or "db"; throws std::invalid_argument naming the parameter.
StepType parse_step_type(std::string_view text);
std::string_view to_string(StepType type);

struct StaircaseSettings {
    double start = 0;  // startVal
    int n_up = 1;      // wrong answers in a row before the intensity goes up
    int n_down = 3;    // correct answers in a row before it goes down
    // The step after 0, 1, 2... reversals (the last one for ever after). 'lin': added
    // or subtracted; 'log': log10 units (x or / 10^step); 'db': decibels
    // (x or / 10^(step/20)).
    std::vector<double> step_sizes{4.0};
    StepType step_type = StepType::db;
    std::optional<double> min_value, max_value;
    int n_trials = 0;                // at least this many trials
    std::optional<int> n_reversals;  // at least this many reversals (see above)
    bool apply_initial_rule = true;  // 1-up/1-down until the first reversal
};

class Staircase final : public AdaptiveProcedure {
public:
    // Throws std::invalid_argument (one line naming the parameter) for a non-finite
    // or out-of-range start, empty or negative step sizes, n_up or n_down below 1,
    // min_value above max_value, and a non-positive start with 'log' or 'db' steps.
    explicit Staircase(StaircaseSettings settings);

    Proposal next() override;
    void add_response(bool correct, std::optional<double> shown = std::nullopt) override;
    bool finished() const override { return finished_; }
    const std::vector<double>& intensities() const override { return intensities_; }
    const std::vector<int>& responses() const override { return responses_; }
    bool hit_range() const override;

    const StaircaseSettings& settings() const { return settings_; }
    int n_reversals() const { return n_reversals_; }  // after PsychoPy's raise
    // The intensity next() will propose, and whether it was held at a bound.
    Proposal upcoming() const { return {next_intensity_, next_clamped_}; }
    double step_size() const { return step_; }  // the step in use now
    // Trial indices (0-based, as PsychoPy's reversalPoints) and intensities of the
    // reversals.
    const std::vector<int>& reversal_trials() const { return reversal_trials_; }
    const std::vector<double>& reversal_intensities() const {
        return reversal_intensities_;
    }
    // Per trial: its proposal was held at a bound.
    const std::vector<bool>& clamped_trials() const { return clamped_; }

private:
    enum class Direction { start, up, down };
    void step_up();
    void step_down();
    void choose_next();

    StaircaseSettings settings_;
    int n_reversals_ = 1;
    double step_ = 0;
    double next_intensity_ = 0;
    bool next_clamped_ = false;
    Direction direction_ = Direction::start;
    int run_ = 0;  // correct answers in a row (negative: wrong answers in a row)
    bool first_reversal_step_ = false;
    bool pending_ = false;
    bool finished_ = false;
    std::vector<double> intensities_;
    std::vector<int> responses_;
    std::vector<bool> clamped_;
    std::vector<int> reversal_trials_;
    std::vector<double> reversal_intensities_;
};

// The order in which interleaved procedures take turns, as MultiStairHandler's method:
// `sequential` (in the given order each round), `random` (each round a seeded shuffle
// of those still running: no procedure runs twice in a row within a round),
// `full_random` (each turn of a round drawn with replacement).
enum class InterleaveOrder { sequential, random, full_random };
InterleaveOrder parse_interleave_order(std::string_view text);  // throws invalid_argument

// Interleaved staircases and/or QUESTs: picks which runs next and routes the answer to
// it; a procedure leaves the rounds once finished. The shuffle uses std::mt19937_64
// and its own unbiased draw, so a seed gives the same order on every platform (not
// numpy's order for the same seed).
class Interleaved {
public:
    Interleaved(std::vector<std::unique_ptr<AdaptiveProcedure>> procedures,
                std::uint64_t seed, InterleaveOrder order = InterleaveOrder::random);

    struct Trial {
        std::size_t procedure = 0;  // index into the list given
        Proposal proposal;
    };
    // The next trial: which procedure and its intensity. Throws std::logic_error when
    // finished() or when the previous trial has no response yet.
    Trial next();
    // The answer to the last trial, given to its procedure.
    void add_response(bool correct, std::optional<double> shown = std::nullopt);
    bool finished() const { return running_.empty(); }
    std::size_t size() const { return procedures_.size(); }
    const AdaptiveProcedure& procedure(std::size_t index) const;
    std::size_t total_trials() const { return total_trials_; }

private:
    void start_round();

    std::vector<std::unique_ptr<AdaptiveProcedure>> procedures_;
    InterleaveOrder order_;
    std::mt19937_64 rng_;
    std::vector<std::size_t> running_;     // not finished, in the given order
    std::vector<std::size_t> this_round_;  // still to run this round, front first
    std::optional<std::size_t> current_;   // the procedure awaiting a response
    std::size_t total_trials_ = 0;
};

}  // namespace lucent::study::adaptive
