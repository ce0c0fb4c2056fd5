#pragma once
// The protocol's [analysis] plan checked against the analysis's registry: study code
// cannot see analysis/models/, so the commands that take a protocol (run, serve) and the
// one that reads a stored one (analyze) check here that its primary_model is an
// analysis Lucent has, before a session starts or a report is written.
#include "study/protocol.h"

namespace lucent::app {

// Throws study::ProtocolError naming the file, line and key when the plan's
// primary_model is neither "anova" nor a registered rating model.
void check_analysis_plan(const study::Protocol& protocol);

}  // namespace lucent::app
