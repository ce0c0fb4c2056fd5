#include "study/adaptive/staircase.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/number_text.h"
#include "common/portable_random.h"

namespace lucent::study::adaptive {
namespace {

[[noreturn]] void refuse(const std::string& message) {
    throw std::invalid_argument("staircase: " + message);
}

std::string number(double v) { return common::shortest_text(v); }

using common::uniform_below;

}  // namespace

StepType parse_step_type(std::string_view text) {
    if (text == "lin") return StepType::lin;
    if (text == "log") return StepType::log;
    if (text == "db") return StepType::db;
    refuse("stepType must be 'lin', 'log' or 'db', not '" + std::string(text) + "'");
}

std::string_view to_string(StepType type) {
    switch (type) {
        case StepType::lin:
            return "lin";
        case StepType::log:
            return "log";
        case StepType::db:
            return "db";
    }
    return "lin";
}

Staircase::Staircase(StaircaseSettings settings) : settings_(std::move(settings)) {
    const StaircaseSettings& s = settings_;
    if (!std::isfinite(s.start)) refuse("startVal must be finite");
    if (s.step_sizes.empty()) refuse("stepSizes must name at least one step");
    for (double step : s.step_sizes)
        if (!std::isfinite(step) || step < 0)
            refuse("stepSizes must be finite and not negative (got " + number(step) +
                   ")");
    if (s.n_up < 1) refuse("nUp must be at least 1 (got " + std::to_string(s.n_up) + ")");
    if (s.n_down < 1)
        refuse("nDown must be at least 1 (got " + std::to_string(s.n_down) + ")");
    if (s.n_trials < 0)
        refuse("nTrials must not be negative (got " + std::to_string(s.n_trials) + ")");
    if (s.n_reversals && *s.n_reversals < 0)
        refuse("nReversals must not be negative (got " + std::to_string(*s.n_reversals) +
               ")");
    if ((s.min_value && !std::isfinite(*s.min_value)) ||
        (s.max_value && !std::isfinite(*s.max_value)))
        refuse("minVal and maxVal must be finite");
    if (s.min_value && s.max_value && *s.min_value > *s.max_value)
        refuse("minVal " + number(*s.min_value) + " is above maxVal " +
               number(*s.max_value));
    if (s.step_type != StepType::lin && s.start <= 0)
        refuse("startVal must be positive with '" + std::string(to_string(s.step_type)) +
               "' steps (got " + number(s.start) + ")");
    if ((s.min_value && s.start < *s.min_value) ||
        (s.max_value && s.start > *s.max_value))
        refuse("startVal " + number(s.start) + " is outside [minVal, maxVal]");

    // PsychoPy: never fewer reversals than step sizes.
    const int n_steps = static_cast<int>(s.step_sizes.size());
    n_reversals_ = std::max(s.n_reversals.value_or(n_steps), n_steps);
    step_ = s.step_sizes.front();
    next_intensity_ = s.start;
}

bool Staircase::hit_range() const {
    return std::find(clamped_.begin(), clamped_.end(), true) != clamped_.end();
}

Proposal Staircase::next() {
    if (finished_)
        throw std::logic_error("staircase: next() after the staircase finished");
    if (pending_)
        throw std::logic_error("staircase: next() before the response to trial " +
                               std::to_string(intensities_.size() - 1));
    pending_ = true;
    intensities_.push_back(next_intensity_);
    clamped_.push_back(next_clamped_);
    return {next_intensity_, next_clamped_};
}

void Staircase::add_response(bool correct, std::optional<double> shown) {
    if (!pending_)
        throw std::logic_error("staircase: a response without a trial (next())");
    if (shown && !std::isfinite(*shown))
        throw std::invalid_argument("staircase: the intensity shown must be finite");
    pending_ = false;
    if (shown) intensities_.back() = *shown;
    const int answer = correct ? 1 : 0;
    const bool same_as_before = !responses_.empty() && responses_.back() == answer;
    responses_.push_back(answer);
    if (correct)
        run_ = same_as_before ? run_ + 1 : 1;
    else
        run_ = same_as_before ? run_ - 1 : -1;
    choose_next();
}

void Staircase::choose_next() {
    const StaircaseSettings& s = settings_;
    const bool correct = responses_.back() == 1;
    const bool initial_phase = reversal_intensities_.empty() && s.apply_initial_rule;

    bool reversal = false;
    if (initial_phase) {
        reversal = direction_ == (correct ? Direction::up : Direction::down);
        direction_ = correct ? Direction::down : Direction::up;
    } else if (run_ >= s.n_down) {
        reversal = direction_ == Direction::up;
        direction_ = Direction::down;
    } else if (run_ <= -s.n_up) {
        reversal = direction_ == Direction::down;
        direction_ = Direction::up;
    }

    if (reversal) {
        if (initial_phase) first_reversal_step_ = true;
        reversal_trials_.push_back(static_cast<int>(intensities_.size()) - 1);
        reversal_intensities_.push_back(intensities_.back());
    }

    if (static_cast<int>(reversal_intensities_.size()) >= n_reversals_ &&
        static_cast<int>(intensities_.size()) >= s.n_trials)
        finished_ = true;

    if (reversal && s.step_sizes.size() > 1)
        step_ =
            s.step_sizes[std::min(reversal_intensities_.size(), s.step_sizes.size() - 1)];

    // The initial rule also steps the first reversal itself.
    if ((reversal_intensities_.empty() || first_reversal_step_) && s.apply_initial_rule) {
        first_reversal_step_ = false;
        if (correct)
            step_down();
        else
            step_up();
    } else if (run_ >= s.n_down) {
        step_down();
    } else if (run_ <= -s.n_up) {
        step_up();
    }
}

void Staircase::step_up() {
    switch (settings_.step_type) {
        case StepType::db:
            next_intensity_ *= std::pow(10.0, step_ / 20.0);
            break;
        case StepType::log:
            next_intensity_ *= std::pow(10.0, step_);
            break;
        case StepType::lin:
            next_intensity_ += step_;
            break;
    }
    next_clamped_ = settings_.max_value && next_intensity_ > *settings_.max_value;
    if (next_clamped_) next_intensity_ = *settings_.max_value;
    run_ = 0;
}

void Staircase::step_down() {
    switch (settings_.step_type) {
        case StepType::db:
            next_intensity_ /= std::pow(10.0, step_ / 20.0);
            break;
        case StepType::log:
            next_intensity_ /= std::pow(10.0, step_);
            break;
        case StepType::lin:
            next_intensity_ -= step_;
            break;
    }
    run_ = 0;
    next_clamped_ = settings_.min_value && next_intensity_ < *settings_.min_value;
    if (next_clamped_) next_intensity_ = *settings_.min_value;
}

InterleaveOrder parse_interleave_order(std::string_view text) {
    if (text == "sequential") return InterleaveOrder::sequential;
    if (text == "random") return InterleaveOrder::random;
    if (text == "fullRandom" || text == "full_random")
        return InterleaveOrder::full_random;
    throw std::invalid_argument(
        "interleaved staircases: order must be 'sequential', 'random' or 'fullRandom', "
        "not '" +
        std::string(text) + "'");
}

Interleaved::Interleaved(std::vector<std::unique_ptr<AdaptiveProcedure>> procedures,
                         std::uint64_t seed, InterleaveOrder order)
    : procedures_(std::move(procedures)), order_(order), rng_(seed) {
    if (procedures_.empty())
        throw std::invalid_argument("interleaved staircases: no staircase given");
    for (std::size_t i = 0; i < procedures_.size(); ++i) {
        if (!procedures_[i])
            throw std::invalid_argument("interleaved staircases: staircase " +
                                        std::to_string(i) + " is missing");
        if (!procedures_[i]->finished()) running_.push_back(i);
    }
}

void Interleaved::start_round() {
    this_round_ = running_;
    const std::size_t n = this_round_.size();
    if (order_ == InterleaveOrder::random) {
        common::portable_shuffle(this_round_, rng_);
    } else if (order_ == InterleaveOrder::full_random) {
        for (std::size_t i = 0; i < n; ++i)
            this_round_[i] = running_[uniform_below(rng_, n)];
    }
}

Interleaved::Trial Interleaved::next() {
    if (current_)
        throw std::logic_error("interleaved staircases: next() before the last response");
    for (;;) {
        if (finished())
            throw std::logic_error("interleaved staircases: next() after all finished");
        if (this_round_.empty()) start_round();
        const std::size_t index = this_round_.front();
        this_round_.erase(this_round_.begin());
        // A full_random round may name a procedure that finished earlier in the round.
        if (procedures_[index]->finished()) continue;
        current_ = index;
        return {index, procedures_[index]->next()};
    }
}

void Interleaved::add_response(bool correct, std::optional<double> shown) {
    if (!current_)
        throw std::logic_error("interleaved staircases: a response without a trial");
    const std::size_t index = *current_;
    procedures_[index]->add_response(correct, shown);
    current_.reset();
    ++total_trials_;
    if (procedures_[index]->finished())
        running_.erase(std::find(running_.begin(), running_.end(), index));
}

const AdaptiveProcedure& Interleaved::procedure(std::size_t index) const {
    if (index >= procedures_.size())
        throw std::out_of_range("interleaved staircases: no staircase " +
                                std::to_string(index));
    return *procedures_[index];
}

}  // namespace lucent::study::adaptive
