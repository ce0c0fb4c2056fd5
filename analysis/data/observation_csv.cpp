#include "analysis/data/observation_csv.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "analysis/data/choice_table.h"
#include "analysis/data/long_table.h"
#include "analysis/data/table_records.h"
#include "common/csv.h"
#include "common/number_text.h"

namespace lucent::analysis {
namespace {

const std::set<std::string> kMeasures = {"start_value", "adjustments", "intensity",
                                         "value_1",     "value_2",     "value_3",
                                         "value_4"};
const std::set<std::string> kFixed = {
    "participant", "session",  "trial",    "block",    "kind",
    "analysed_as", "question", "practice", "catch",    "expected",
    "shown",       "response", "rt_ms",    "procedure"};
const std::set<std::string> kAnalyses = {"ratings", "choices", "matches", "thresholds",
                                         ""};

// What a built-in kind is analysed as, for a file without the analysed_as column (the
// analysis cannot ask the study's registry of kinds); nullopt for any other kind.
std::optional<std::string> built_in_analysis(const std::string& kind) {
    if (kind == "rating") return "ratings";
    if (kind == "adjust") return "matches";
    if (kind == "staircase") return "thresholds";
    if (parse_choice_task(kind)) return "choices";
    return std::nullopt;
}

// One data row's cells by column name; every message names "source:line: column N
// (name)".
class Cells {
public:
    Cells(const std::string& source, std::size_t line,
          const std::map<std::string, std::size_t>& column,
          const std::vector<std::string>& fields)
        : source_(source), line_(line), column_(column), fields_(fields) {}

    std::string text(const std::string& name) const {
        const auto it = column_.find(name);
        return it == column_.end() ? std::string() : fields_[it->second];
    }
    [[noreturn]] void fail(const std::string& name, const std::string& why) const {
        const auto it = column_.find(name);
        throw InputError(
            source_ + ":" + std::to_string(line_) + ": column " +
            (it == column_.end() ? std::string("?") : std::to_string(it->second + 1)) +
            " (" + name + "): " + why);
    }
    std::optional<double> number(const std::string& name) const {
        const std::string t = text(name);
        if (t.empty()) return std::nullopt;
        const auto v = common::parse_finite_number(t);
        if (!v) fail(name, "'" + t + "' is not a finite number");
        return v;
    }
    std::optional<long long> integer(const std::string& name) const {
        const std::string t = text(name);
        if (t.empty()) return std::nullopt;
        long long v = 0;
        const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (error != std::errc() || end != t.data() + t.size())
            fail(name, "'" + t + "' is not a whole number");
        return v;
    }
    bool flag(const std::string& name) const {
        const auto v = integer(name);
        if (v && *v != 0 && *v != 1)
            fail(name, "expected 0 or 1, got '" + text(name) + "'");
        return v.value_or(0) == 1;
    }

private:
    const std::string& source_;
    std::size_t line_;
    const std::map<std::string, std::size_t>& column_;
    const std::vector<std::string>& fields_;
};

}  // namespace

bool is_observation_header(const std::string& header_line) {
    const std::vector<std::string> fields = common::split_csv_line(header_line);
    return std::count(fields.begin(), fields.end(), "kind") == 1 &&
           std::count(fields.begin(), fields.end(), "response") == 1;
}

common::ObservationTable read_observation_csv(std::istream& in,
                                              const std::string& source) {
    common::ObservationTable table;
    std::map<std::string, std::size_t> column;
    std::vector<std::pair<std::string, std::size_t>> factors;  // name, column
    TableRecords records(in, source);
    const std::vector<std::string>& head = records.header();
    for (std::size_t f = 0; f < head.size(); ++f) {
        const std::string& name = head[f];
        const bool is_factor = !kFixed.count(name) && !kMeasures.count(name);
        const std::string key =
            is_factor && name.rfind("factor:", 0) == 0 ? name.substr(7) : name;
        // Fixed columns and factors are apart: "factor:trial" is no "trial".
        const bool taken =
            is_factor ? std::any_of(factors.begin(), factors.end(),
                                    [&](const auto& c) { return c.first == key; })
                      : column.count(key) > 0;
        if (key.empty() || taken)
            throw InputError(source + ":" + std::to_string(records.header_line()) +
                             ": column " + std::to_string(f + 1) + ": '" + name +
                             (key.empty() ? "' is an empty name" : "' twice"));
        if (is_factor)
            factors.emplace_back(key, f);
        else
            column[key] = f;
    }
    for (const char* required : {"participant", "kind", "response"})
        if (!column.count(required))
            throw InputError(source + ":" + std::to_string(records.header_line()) +
                             ": header lacks column '" + std::string(required) +
                             "' (expected the columns of lucent export --format "
                             "observations)");
    std::vector<std::string> fields;
    while (records.next(fields)) {
        const std::size_t first_line = records.line();
        const Cells cell(source, first_line, column, fields);
        common::Observation row;
        row.participant = cell.text("participant");
        if (row.participant.empty()) cell.fail("participant", "participant is empty");
        row.kind = cell.text("kind");
        if (row.kind.empty()) cell.fail("kind", "kind is empty");
        if (column.count("analysed_as")) {
            row.analysed_as = cell.text("analysed_as");
            if (!kAnalyses.count(row.analysed_as))
                cell.fail("analysed_as",
                          "'" + row.analysed_as +
                              "' is not one of ratings, choices, matches, thresholds or "
                              "empty");
            if (row.analysed_as == "choices" && !parse_choice_task(row.kind))
                cell.fail("analysed_as", "a " + row.kind +
                                             " trial is not a pair, triad or quadruple: "
                                             "the scaling reads no other choice");
        } else if (const auto analysis = built_in_analysis(row.kind)) {
            row.analysed_as = *analysis;
        } else {
            cell.fail("kind", "'" + row.kind +
                                  "' is not one of rating, pair, triad, quadruple, "
                                  "adjust, staircase (another kind needs the analysed_as "
                                  "column)");
        }
        row.session = cell.text("session");
        row.trial = static_cast<int>(cell.integer("trial").value_or(0));
        row.block = cell.text("block");
        row.question = cell.text("question");
        row.practice = cell.flag("practice");
        row.is_catch = cell.flag("catch");
        if (const auto e = cell.integer("expected")) row.expected = static_cast<int>(*e);
        const std::string shown = cell.text("shown");
        for (std::size_t start = 0; start < shown.size();) {
            std::size_t end = shown.find(' ', start);
            if (end == std::string::npos) end = shown.size();
            if (end > start) row.shown.push_back(shown.substr(start, end - start));
            start = end + 1;
        }
        const auto scaling = parse_choice_task(row.kind);
        const std::size_t pictures =
            scaling ? static_cast<std::size_t>(shown_count(*scaling)) : 1;
        if (!row.analysed_as.empty() && row.shown.size() != pictures)
            cell.fail("shown", "a " + row.kind + " shows " + std::to_string(pictures) +
                                   (pictures == 1 ? " stimulus" : " stimuli") + ", " +
                                   std::to_string(row.shown.size()) + " are named");
        row.response = cell.number("response");
        row.rt_ms = cell.number("rt_ms").value_or(0.0);
        row.procedure = cell.text("procedure");
        for (const std::string& measure : kMeasures)
            if (const auto v = cell.number(measure)) row.measures[measure] = *v;
        for (const auto& [name, f] : factors)
            if (!fields[f].empty()) row.factors.emplace_back(name, fields[f]);
        table.rows.push_back(std::move(row));
    }
    return table;
}

common::ObservationTable read_observation_csv(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot open for reading");
    return read_observation_csv(in, path.string());
}

}  // namespace lucent::analysis
