#include "analysis/data/matching_table.h"

namespace lucent::analysis {
namespace {

// Where a row was answered: the fields MatchRow and StaircaseRow share.
template <typename Row>
Row answered_at(const common::Observation& o) {
    Row row;
    row.participant = o.participant;
    row.session = o.session;
    row.trial = o.trial;
    row.block = o.block;
    row.rt_ms = o.rt_ms;
    return row;
}

}  // namespace

MatchingTable matching_of(const common::ObservationTable& observations,
                          std::optional<study::Protocol> protocol) {
    MatchingTable table;
    table.protocol = std::move(protocol);
    for (const common::Observation& o : observations.rows) {
        if (o.practice || o.shown.empty()) continue;
        const auto measure = [&o](const char* name) -> std::optional<double> {
            const auto it = o.measures.find(name);
            return it != o.measures.end() ? std::optional(it->second) : std::nullopt;
        };
        if (o.analysed_as == "matches" && o.response) {
            MatchRow row = answered_at<MatchRow>(o);
            row.target = o.shown.front();
            if (table.protocol)
                if (const study::Block* b = table.protocol->find_block(row.block)) {
                    row.match = b->match;
                    row.knob = b->knob;
                }
            row.start_value = measure("start_value");
            row.final_value = *o.response;
            row.adjustments = static_cast<int>(measure("adjustments").value_or(0));
            table.matches.push_back(std::move(row));
        } else if (o.analysed_as == "thresholds" && measure("intensity") && o.expected) {
            StaircaseRow row = answered_at<StaircaseRow>(o);
            row.standard = o.shown.front();
            row.staircase = o.procedure;
            row.intensity = *measure("intensity");
            row.expected = *o.expected;
            row.choice = static_cast<int>(o.response.value_or(0));
            row.correct = row.choice == row.expected;
            table.staircases.push_back(std::move(row));
        }
    }
    return table;
}

}  // namespace lucent::analysis
