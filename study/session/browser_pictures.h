#pragma once
// Every picture `lucent serve` shows for a protocol, as a stimulus set that `lucent
// render --study` renders through the batch renderer: each live protocol stimulus and
// each picture of the adjust blocks' series and the staircase blocks' ladders
// (web_series.h). The set's manifest is then what `lucent serve --images` checks every
// picture against, series included.
#include "renderer/core/stimulus_set.h"
#include "study/protocol.h"

namespace lucent::study {

// Throws ProtocolError (a series the browser cannot show) or StimulusError (a stimulus
// whose parameters its technique refuses), one line naming the stimulus.
StimulusSet browser_picture_set(const Protocol& protocol,
                                const SetCatalog& catalog = default_set_catalog());

}  // namespace lucent::study
