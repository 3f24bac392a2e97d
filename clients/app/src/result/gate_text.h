// The texts of the CI gate's parts (gate.cc, gate_rules.cc, gate_report.cc), in one place so that
// a metric name written by one part is the name another part matches.
#pragma once

#include <fmt/format.h>

#include <string>

namespace driftlab::app {

// A time in a metric name ("epoch[t=600]"): the shortest text that reads back as the same double.
inline std::string MetricTimeText(double t_s) { return fmt::format("{}", t_s); }

// A number in the gate's messages and tables: 6 significant digits.
inline std::string GateNumberText(double value) { return fmt::format("{:.6g}", value); }

}  // namespace driftlab::app
