#pragma once
// `lucent merge FILES... --out postgresql://...`: station files into a study server.
//
// The files are merged with the server's own snapshot by merge_databases (the same
// checks: one protocol, stimuli resolved alike, copies of a session reconciled by UUID,
// withdrawals honoured, a code from several machines kept apart), then in one
// transaction: what the server lacks is inserted, with new row ids and every reference
// mapped; a server session that a file's copy extends gets the missing trials' ratings,
// segments and status (the server's session stays, with its id); the inputs'
// withdrawal tombstones are added and the server's sessions they cover deleted. A code
// the server holds that the merge would rename (the same code from another machine, or
// two people on one machine) is refused: merge into a file then. `names` name the
// files in messages (default: their paths).
#include <string>
#include <vector>

#include "study/export.h"

namespace lucent::study {

MergeReport merge_into_server(const std::vector<std::string>& files,
                              const std::string& uri,
                              const std::vector<std::string>& names = {});

}  // namespace lucent::study
