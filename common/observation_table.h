#pragma once
// The one table a study's answers reach the statistics in (issue 51): one row per
// observation, whatever its trial kind (a rating of one question, a forced choice, a
// confirmed match, a staircase choice), each with the factors of its stimulus as named
// columns. study/observations.h fills it from a study database (a server's through its
// snapshot); analysis/ reads its ratings, choices and matches out of it; `lucent export
// --format observations` writes it as one wide CSV.
#include <cstddef>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace lucent::common {

struct Observation {
    std::string participant;  // the participant code
    std::string session;      // the session's UUID
    int trial = 0;            // the trial's position in the session
    std::string block;
    std::string kind;  // the trial kind: rating, pair, triad, quadruple, adjust, ...
    // What the analysis reads it as (its kind says: TrialKind::analysed_as): "ratings"
    // (the factor ratings' tests and models), "choices" (the scaling), "matches",
    // "thresholds", or "" (none: exported, not analysed).
    std::string analysed_as;
    std::string question;  // the question answered; "" where the kind asks none
    bool practice = false;
    bool is_catch = false;
    std::optional<int> expected;  // the right answer, where the trial has one
    // The stimuli in screen order: a rating's one, a forced choice's 2 to 4, an adjust
    // trial's target, a staircase trial's standard.
    std::vector<std::string> shown;
    // The factors of a one-stimulus trial's stimulus, (name, level), in its own order:
    // the parameters it varies (or all of them), "technique" when listed, a comparison
    // series as its stimulus id. Empty for forced choices, whose stimuli differ in them.
    std::vector<std::pair<std::string, std::string>> factors;
    // A rating; a forced choice (1 or 2); an adjust trial's confirmed value; a staircase
    // trial's place chosen. Empty where none was stored.
    std::optional<double> response;
    double rt_ms = 0;
    // The kind's other numbers by name: adjust "start_value", "adjustments"; staircase
    // "intensity"; forced choices "value_1".."value_4" (each shown stimulus's value of
    // the block's series parameter, where it has one).
    std::map<std::string, double> measures;
    std::string procedure;  // staircase: its procedure, "<standard>/<procedure id>"
};

struct ObservationTable {
    std::vector<Observation> rows;
    // The factor names of every row, each once, in the order first met: the wide CSV's
    // factor columns.
    std::vector<std::string> factor_columns() const;
};

// A rating trial's answer on one of its stimulus's factors: the long table the one-way
// tests and mixed models read (practice and catch trials never enter).
struct FactorRating {
    const Observation* observation = nullptr;
    const std::string* factor = nullptr;
    const std::string* level = nullptr;
};
std::vector<FactorRating> factor_ratings(const ObservationTable& table);

// participant,session,trial,block,kind,question,practice,catch,expected,shown (ids
// joined by spaces),response,rt_ms,procedure, one column per measure met, then one per
// factor (factor_columns(); a factor named like a fixed column gets the prefix
// "factor:"). Numbers in their shortest exact text; an absent value is an empty field.
void write_observation_csv(std::ostream& out, const ObservationTable& table);

}  // namespace lucent::common
