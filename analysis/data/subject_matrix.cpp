#include "analysis/data/subject_matrix.h"

#include <unordered_map>

namespace lucent::analysis {

SubjectMatrix subject_by_level(const LongTable& table, const std::string& question,
                               const std::string& factor,
                               const std::vector<std::string>& levels) {
    // Labels are interned: the maps hash and compare pointers, not texts.
    const Label question_label(question), factor_label(factor);
    std::unordered_map<Label, std::size_t> level_column;
    for (std::size_t j = 0; j < levels.size(); ++j) level_column.emplace(levels[j], j);
    std::vector<std::string> participants;
    std::unordered_map<Label, std::size_t> participant_row;
    struct Cell {
        long double sum = 0.0L;
        std::size_t count = 0;
    };
    std::vector<std::vector<Cell>> cells;
    // Rows come in runs of one participant and level: the previous row's cell is
    // checked first.
    const RatingRow* previous = nullptr;
    std::size_t row_at = 0, column_at = 0;
    for (const RatingRow& row : table.rows) {
        if (!row.rating || row.question != question_label || row.factor != factor_label)
            continue;
        if (!previous || row.level != previous->level) {
            const auto column = level_column.find(row.level);
            if (column == level_column.end()) continue;
            column_at = column->second;
        }
        if (!previous || row.participant != previous->participant) {
            auto [it, inserted] =
                participant_row.emplace(row.participant, participants.size());
            if (inserted) {
                participants.push_back(row.participant);
                cells.emplace_back(levels.size());
            }
            row_at = it->second;
        }
        previous = &row;
        Cell& cell = cells[row_at][column_at];
        cell.sum += *row.rating;
        ++cell.count;
    }
    SubjectMatrix m;
    m.complete.levels = levels;
    for (std::size_t i = 0; i < participants.size(); ++i) {
        bool complete = true;
        for (const Cell& c : cells[i]) complete = complete && c.count > 0;
        if (!complete) {
            m.incomplete_participants.push_back(participants[i]);
            continue;
        }
        m.complete.participants.push_back(participants[i]);
        for (const Cell& c : cells[i])
            m.complete.values.push_back(
                static_cast<double>(c.sum / static_cast<long double>(c.count)));
    }
    return m;
}

}  // namespace lucent::analysis
