#pragma once
// The within-subject layout of one (question, factor) pair: each participant's mean
// rating at each level of the factor (the mean over that level's stimuli and repeats).
#include <string>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/stats/repeated_measures.h"

namespace lucent::analysis {

struct SubjectMatrix {
    SubjectByLevel complete;  // participants who rated every level, in first-seen order
    // Participants with a rating at some level of the factor but not at every level.
    std::vector<std::string> incomplete_participants;
};

// `levels` fixes the columns and their order (the between-subject groups' order); a
// row without a rating counts as not rated.
SubjectMatrix subject_by_level(const LongTable& table, const std::string& question,
                               const std::string& factor,
                               const std::vector<std::string>& levels);

}  // namespace lucent::analysis
