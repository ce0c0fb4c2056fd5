#pragma once
// The provenance part of `lucent merge` (schema 3): refusing inputs whose stimuli of one
// id resolved to different values, and copying segments and what they showed.
#include <string>
#include <vector>

#include "study/sqlite/database.h"

namespace lucent::study {

// Throws StoreError (one line naming both files, the stimulus and the parameter) when
// two inputs recorded different resolved values, technique, mesh or mesh hash for a
// stimulus id. Inputs without recorded values are not compared. Reads only.
void check_resolved_stimuli_agree(const std::vector<std::string>& inputs);

// With the input attached as `src` and merge's own rows (stimuli, sessions, trials and
// temp.new_sessions) copied: the resolved values main lacks, the new sessions' segments,
// what each segment showed, and each new trial's segment.
void copy_provenance(Database& db);

}  // namespace lucent::study
