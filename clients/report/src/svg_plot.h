// The reports' shared style sheet and number format (html_report.cc: Monte-Carlo result;
// calibration_report.cc: calibration and Allan noise fit). The plots themselves are interactive
// (interactive_plot.h).
#pragma once

#include <string>

#include "driftlab/report/html_report.h"

namespace driftlab::app::svg {

// "{:.4g}" of a value (tables, captions).
std::string Num(double value);

// The reports' style sheet (a <style> element).
inline constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; }
.grid { display: flex; flex-wrap: wrap; gap: 0.5em; }
figure { margin: 0.3em; } figcaption { font-size: 0.85em; max-width: 520px; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.5em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
caption { text-align: left; font-weight: bold; padding: 0.3em 0; }
pre { background: #f4f4f4; padding: 0.8em; overflow-x: auto; font-size: 0.85em; }
.key { display: inline-block; width: 2em; height: 0.6em; margin: 0 0.3em 0 1em; }
</style>
)";

}  // namespace driftlab::app::svg
