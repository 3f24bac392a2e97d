// HTML report of a Monte-Carlo result: one self-contained file (inline SVG and CSS, no script, no
// external resource), readable offline and attachable to a design review or a CI artifact.
//
// Contents: the job's name and description; engine version, seed, runs, run range, timings;
// summary table of the final epoch (mean, sigma and RMS with their 95 % confidence intervals,
// percentiles of |error|, CEP50/CEP95/2DRMS) and a percentile table per further checkpoint; error
// envelopes against time per component (mean +- sigma band, mean, +-RMS); the final horizontal
// scatter (east vs north per run, with the CEP50 and CEP95 circles about the true position);
// histograms of the final horizontal error and of every other component; the job echo as JSON.
// All text from the result is HTML-escaped. Angles in degrees, other units SI, as in the result.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "driftlab/v1/result.pb.h"

namespace driftlab::jobspec {

// The report for a valid result (ValidateJobResult); the HTML text.
std::string RenderHtmlReport(const v1::JobResult& result);

// Escapes & < > " ' for HTML text and attribute values.
std::string EscapeHtml(std::string_view text);

// Axis ticks at "nice" numbers (1, 2 or 5 times a power of ten) covering [lo, hi] with about
// `target` ticks: Heckbert, "Nice numbers for graph labels", Graphics Gems (1990), pp. 61-63.
struct AxisTicks {
  double lo = 0;               // first tick (<= the data's lo)
  double hi = 0;               // last tick (>= the data's hi)
  double step = 0;             // tick spacing
  int decimals = 0;            // digits after the point that print `step` exactly
  std::vector<double> values;  // lo, lo + step, ..., hi
};
AxisTicks NiceTicks(double lo, double hi, int target = 5);

}  // namespace driftlab::jobspec
