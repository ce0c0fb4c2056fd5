#include "analysis/data/choice_table.h"

#include <array>
#include <charconv>
#include <fstream>
#include <sstream>

#include "analysis/data/long_table.h"
#include "analysis/data/table_records.h"
#include "common/csv.h"
#include "common/number_text.h"

namespace lucent::analysis {
namespace {

// Every column the writer writes, in its order; the reader finds them by name.
constexpr std::array<const char*, 19> kColumns{
    "participant", "session",  "trial",   "block",   "task",    "question", "practice",
    "catch",       "expected", "shown_1", "shown_2", "shown_3", "shown_4",  "value_1",
    "value_2",     "value_3",  "value_4", "choice",  "rt_ms"};
enum Column {
    kParticipant,
    kSession,
    kTrial,
    kBlock,
    kTask,
    kQuestion,
    kPractice,
    kCatch,
    kExpected,
    kShown1,
    kValue1 = kShown1 + 4,
    kChoice = kValue1 + 4,
    kRt,
};
// Without these a row says nothing a scaling can use; the rest default (session and
// block empty, not practice, not catch, no values, RT 0).
constexpr std::array<Column, 4> kRequired{kParticipant, kTask, kShown1, kChoice};

std::string trimmed(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return std::string(s);
}

// Reads one row's cells; every message names "source:line: column N (name)".
class RowReader {
public:
    RowReader(const std::string& source, std::size_t line,
              const std::array<int, kColumns.size()>& column,
              const std::vector<std::string>& fields)
        : source_(source), line_(line), column_(column), fields_(fields) {}

    std::string text(int c) const {
        return column_[c] < 0 ? std::string() : trimmed(fields_[column_[c]]);
    }
    [[noreturn]] void fail(int c, const std::string& why) const {
        throw InputError(source_ + ":" + std::to_string(line_) + ": column " +
                         std::to_string(column_[c] + 1) + " (" + kColumns[c] +
                         "): " + why);
    }
    std::optional<long long> integer(int c) const {
        const std::string t = text(c);
        if (t.empty()) return std::nullopt;
        long long v = 0;
        const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (error != std::errc() || end != t.data() + t.size())
            fail(c, "'" + t + "' is not a whole number");
        return v;
    }
    bool flag(int c) const {
        const auto v = integer(c);
        if (v && *v != 0 && *v != 1) fail(c, "expected 0 or 1, got '" + text(c) + "'");
        return v.value_or(0) == 1;
    }
    std::optional<double> number(int c) const {
        const std::string t = text(c);
        if (t.empty() || t == "NA") return std::nullopt;
        const auto v = common::parse_finite_number(t);
        if (!v) fail(c, "'" + t + "' is not a finite number");
        return v;
    }

private:
    const std::string& source_;
    std::size_t line_;
    const std::array<int, kColumns.size()>& column_;
    const std::vector<std::string>& fields_;
};

}  // namespace

std::optional<ChoiceTask> parse_choice_task(const std::string& text) {
    if (text == "pair") return ChoiceTask::pair;
    if (text == "triad") return ChoiceTask::triad;
    if (text == "quadruple") return ChoiceTask::quadruple;
    return std::nullopt;
}

const char* choice_task_name(ChoiceTask task) {
    switch (task) {
        case ChoiceTask::pair:
            return "pair";
        case ChoiceTask::triad:
            return "triad";
        case ChoiceTask::quadruple:
            return "quadruple";
    }
    return "pair";
}

int shown_count(ChoiceTask task) {
    switch (task) {
        case ChoiceTask::pair:
            return 2;
        case ChoiceTask::triad:
            return 3;
        case ChoiceTask::quadruple:
            return 4;
    }
    return 2;
}

ChoiceTable read_choice_csv(std::istream& in, const std::string& source) {
    ChoiceTable table;
    std::array<int, kColumns.size()> column{};
    column.fill(-1);
    TableRecords records(in, source);
    const std::vector<std::string>& head = records.header();
    for (std::size_t f = 0; f < head.size(); ++f)
        for (std::size_t c = 0; c < kColumns.size(); ++c)
            if (trimmed(head[f]) == kColumns[c]) column[c] = static_cast<int>(f);
    for (const Column c : kRequired)
        if (column[c] < 0)
            throw InputError(source + ":" + std::to_string(records.header_line()) +
                             ": header lacks column '" + kColumns[c] +
                             "' (expected the columns of lucent export --format "
                             "choices: participant,...,shown_1,...,choice,rt_ms)");
    if (column[kShown1 + 1] < 0)
        throw InputError(source + ":" + std::to_string(records.header_line()) +
                         ": header lacks column 'shown_2'");
    std::vector<std::string> fields;
    while (records.next(fields)) {
        const std::size_t first_line = records.line();
        const RowReader cell(source, first_line, column, fields);
        if (cell.flag(kPractice)) continue;
        ChoiceRow row;
        row.source_line = first_line;
        row.participant = cell.text(kParticipant);
        if (row.participant.empty()) cell.fail(kParticipant, "participant is empty");
        row.session = cell.text(kSession);
        row.trial = static_cast<int>(cell.integer(kTrial).value_or(0));
        row.block = cell.text(kBlock);
        const auto task = parse_choice_task(cell.text(kTask));
        if (!task)
            cell.fail(kTask, "task '" + cell.text(kTask) +
                                 "' is not one of pair, triad, quadruple");
        row.task = *task;
        row.question = cell.text(kQuestion);
        row.is_catch = cell.flag(kCatch);
        if (const auto e = cell.integer(kExpected)) {
            if (*e != 1 && *e != 2)
                cell.fail(kExpected,
                          "expected 1, 2 or empty, got '" + cell.text(kExpected) + "'");
            row.expected = static_cast<int>(*e);
        }
        for (int k = 0; k < 4; ++k) {
            row.shown[k] = cell.text(kShown1 + k);
            row.value[k] = cell.number(kValue1 + k);
            if (k < shown_count(row.task) && row.shown[k].empty()) {
                if (column[kShown1 + k] < 0)
                    throw InputError(source + ":" + std::to_string(first_line) + ": a " +
                                     choice_task_name(row.task) + " needs column '" +
                                     kColumns[kShown1 + k] + "', which the header lacks");
                cell.fail(kShown1 + k, std::string("a ") + choice_task_name(row.task) +
                                           " shows " +
                                           std::to_string(shown_count(row.task)) +
                                           " stimuli; this one is empty");
            }
        }
        const auto choice = cell.integer(kChoice);
        if (!choice || (*choice != 1 && *choice != 2))
            cell.fail(kChoice, "expected 1 or 2, got '" + cell.text(kChoice) + "'");
        row.choice = static_cast<int>(*choice);
        row.rt_ms = cell.number(kRt).value_or(0.0);
        table.rows.push_back(std::move(row));
    }
    return table;
}

ChoiceTable choices_of(const common::ObservationTable& observations,
                       const std::string& source) {
    ChoiceTable table;
    for (std::size_t i = 0; i < observations.rows.size(); ++i) {
        const common::Observation& o = observations.rows[i];
        if (o.analysed_as != "choices" || o.practice) continue;
        // The scaling's design is the kind's (pair, triad or quadruple).
        const std::optional<ChoiceTask> task = parse_choice_task(o.kind);
        if (!task) continue;
        ChoiceRow row;
        row.source_line = i + 1;
        row.participant = o.participant;
        row.session = o.session;
        row.trial = o.trial;
        row.block = o.block;
        row.task = *task;
        row.question = o.question;
        row.is_catch = o.is_catch;
        row.expected = o.expected;
        const std::size_t n = static_cast<std::size_t>(shown_count(*task));
        if (o.shown.size() < n)
            throw InputError(source + ": session " + o.session + ", trial " +
                             std::to_string(o.trial) + ": a " + choice_task_name(*task) +
                             " shows " + std::to_string(n) + " stimuli; " +
                             std::to_string(o.shown.size()) + " are stored");
        for (std::size_t k = 0; k < n; ++k) {
            row.shown[k] = o.shown[k];
            if (const auto v = o.measures.find("value_" + std::to_string(k + 1));
                v != o.measures.end())
                row.value[k] = v->second;
        }
        if (!o.response || (*o.response != 1 && *o.response != 2))
            throw InputError(source + ": session " + o.session + ", trial " +
                             std::to_string(o.trial) + ": choice " +
                             (o.response ? common::shortest_text(*o.response) : "empty") +
                             ", expected 1 or 2");
        row.choice = static_cast<int>(*o.response);
        row.rt_ms = o.rt_ms;
        table.rows.push_back(std::move(row));
    }
    return table;
}

ChoiceTable read_choice_csv(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot open for reading");
    return read_choice_csv(in, path.string());
}

void write_choice_csv(std::ostream& out, const ChoiceTable& table) {
    for (std::size_t c = 0; c < kColumns.size(); ++c)
        out << (c ? "," : "") << kColumns[c];
    out << '\n';
    for (const ChoiceRow& row : table.rows) {
        out << common::csv_field(row.participant) << ',' << common::csv_field(row.session)
            << ',' << row.trial << ',' << common::csv_field(row.block) << ','
            << choice_task_name(row.task) << ',' << common::csv_field(row.question)
            << ",0," << (row.is_catch ? 1 : 0) << ',';
        if (row.expected) out << *row.expected;
        const int n = shown_count(row.task);
        for (int k = 0; k < 4; ++k)
            out << ',' << (k < n ? common::csv_field(row.shown[k]) : std::string());
        for (int k = 0; k < 4; ++k) {
            out << ',';
            if (k < n && row.value[k]) out << common::shortest_text(*row.value[k]);
        }
        out << ',' << row.choice << ',' << common::shortest_text(row.rt_ms) << '\n';
    }
}

}  // namespace lucent::analysis
