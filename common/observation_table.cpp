#include "common/observation_table.h"

#include <algorithm>
#include <set>

#include "common/csv.h"
#include "common/number_text.h"

namespace lucent::common {
namespace {

constexpr const char* kFixedColumns[] = {
    "participant", "session",  "trial",    "block",    "kind",
    "analysed_as", "question", "practice", "catch",    "expected",
    "shown",       "response", "rt_ms",    "procedure"};

}  // namespace

std::vector<std::string> ObservationTable::factor_columns() const {
    std::vector<std::string> out;
    std::set<std::string> seen;
    for (const Observation& row : rows)
        for (const auto& [name, level] : row.factors)
            if (seen.insert(name).second) out.push_back(name);
    return out;
}

std::vector<FactorRating> factor_ratings(const ObservationTable& table) {
    std::vector<FactorRating> out;
    for (const Observation& row : table.rows) {
        if (row.analysed_as != "ratings" || row.practice || row.is_catch || !row.response)
            continue;
        for (const auto& [factor, level] : row.factors)
            out.push_back({&row, &factor, &level});
    }
    return out;
}

void write_observation_csv(std::ostream& out, const ObservationTable& table) {
    std::vector<std::string> measures;
    {
        std::set<std::string> seen;
        for (const Observation& row : table.rows)
            for (const auto& [name, value] : row.measures)
                if (seen.insert(name).second) measures.push_back(name);
    }
    const std::vector<std::string> factors = table.factor_columns();
    const std::set<std::string> fixed(std::begin(kFixedColumns), std::end(kFixedColumns));
    bool first = true;
    for (const char* column : kFixedColumns) {
        out << (first ? "" : ",") << column;
        first = false;
    }
    for (const std::string& m : measures) out << "," << csv_field(m);
    // A measure or factor spelled like a fixed column would make two columns of one
    // name; the factor gives way.
    for (const std::string& f : factors)
        out << ","
            << csv_field(fixed.count(f) || std::count(measures.begin(), measures.end(), f)
                             ? "factor:" + f
                             : f);
    out << "\n";
    for (const Observation& row : table.rows) {
        std::string shown;
        for (const std::string& id : row.shown) shown += (shown.empty() ? "" : " ") + id;
        out << csv_field(row.participant) << "," << csv_field(row.session) << ","
            << row.trial << "," << csv_field(row.block) << "," << csv_field(row.kind)
            << "," << csv_field(row.analysed_as) << "," << csv_field(row.question) << ","
            << (row.practice ? 1 : 0) << "," << (row.is_catch ? 1 : 0) << ","
            << (row.expected ? std::to_string(*row.expected) : std::string()) << ","
            << csv_field(shown) << ","
            << (row.response ? shortest_text(*row.response) : std::string()) << ","
            << shortest_text(row.rt_ms) << "," << csv_field(row.procedure);
        for (const std::string& m : measures) {
            const auto it = row.measures.find(m);
            out << "," << (it != row.measures.end() ? shortest_text(it->second) : "");
        }
        for (const std::string& f : factors) {
            const auto it = std::find_if(row.factors.begin(), row.factors.end(),
                                         [&](const auto& p) { return p.first == f; });
            out << "," << (it != row.factors.end() ? csv_field(it->second) : "");
        }
        out << "\n";
    }
}

}  // namespace lucent::common
