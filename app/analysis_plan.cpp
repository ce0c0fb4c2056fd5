#include "app/analysis_plan.h"

#include "analysis/models/rating_model.h"

namespace lucent::app {

void check_analysis_plan(const study::Protocol& protocol) {
    const std::string& model = protocol.analysis.primary_model;
    if (model == analysis::kOneWayTests || analysis::find_rating_model(model)) return;
    throw study::ProtocolError((protocol.analysis.primary_model_at.empty()
                                    ? protocol.source + ": key 'analysis.primary_model'"
                                    : protocol.analysis.primary_model_at) +
                               ": must be one of " + analysis::rating_model_names() +
                               ", got '" + model + "'");
}

}  // namespace lucent::app
