#pragma once
// `lucent merge FILES... --out postgresql://...`: station files into a study server.
//
// The files are merged with the server's own snapshot by merge_databases (the same
// checks: one protocol, stimuli resolved alike, sessions de-duplicated by UUID, a code
// from several machines kept apart), then what the server lacks is inserted in one
// transaction, with new row ids and every reference mapped. A code the server holds
// that the merge would rename (the same code from another machine) is refused: merge
// into a file then.
#include <string>
#include <vector>

#include "export.h"

namespace lucent::study {

MergeReport merge_into_server(const std::vector<std::string>& files, const std::string& uri);

}  // namespace lucent::study
