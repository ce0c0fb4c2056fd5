#pragma once
// The table every scaling starts from: one row per forced choice of a paired-comparison
// or difference-scaling (MLDS) trial. The CSV reader fills it from `lucent export
// --format choices`; a study's observations (common/observation_table.h) give the same
// rows.
#include <array>
#include <cstddef>
#include <filesystem>
#include <istream>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "common/observation_table.h"

namespace lucent::analysis {

enum class ChoiceTask { pair, triad, quadruple };

// "pair", "triad", "quadruple"; nullopt for anything else.
std::optional<ChoiceTask> parse_choice_task(const std::string& text);
const char* choice_task_name(ChoiceTask task);
// Stimuli a trial of the task shows: 2, 3 or 4.
int shown_count(ChoiceTask task);

struct ChoiceRow {
    std::string participant;
    std::string session;  // session UUID (or any label of one sitting)
    int trial = 0;        // position in the session
    std::string block;
    ChoiceTask task = ChoiceTask::pair;
    std::string question;  // the block's question id
    bool is_catch = false;
    std::optional<int> expected;  // catch trials with a right answer (1 or 2)
    // Stimulus ids in screen order (left to right, or first to last in sequence); only
    // the first shown_count(task) are used.
    std::array<std::string, 4> shown;
    // The block's series parameter of each shown stimulus (MLDS: its physical value);
    // empty when the block names no series.
    std::array<std::optional<double>, 4> value;
    // pair: 1 = shown[0] chosen, 2 = shown[1];
    // triad: 1 = (shown[0], shown[1]) differs more, 2 = (shown[1], shown[2]);
    // quadruple: 1 = (shown[0], shown[1]) differs more, 2 = (shown[2], shown[3]).
    int choice = 1;
    double rt_ms = 0;
    std::size_t source_line = 0;  // CSV line (or database row) for error messages
};

struct ChoiceTable {
    std::vector<ChoiceRow> rows;  // practice trials never enter
};

// The forced choices (pair, triad, quadruple) of a study's observations, practice
// trials left out; `source` names the study in errors (a choice other than 1 or 2).
ChoiceTable choices_of(const common::ObservationTable& observations,
                       const std::string& source);

// Reads the `choices` CSV (header required, columns in any order, RFC 4180 quotes);
// rows with practice = 1 are skipped. Throws InputError naming source:line and the field.
ChoiceTable read_choice_csv(std::istream& in, const std::string& source);
ChoiceTable read_choice_csv(const std::filesystem::path& path);
// The same columns (practice always 0): participant,session,trial,block,task,question,
// practice,catch,expected,shown_1..shown_4,value_1..value_4,choice,rt_ms.
void write_choice_csv(std::ostream& out, const ChoiceTable& table);

}  // namespace lucent::analysis
