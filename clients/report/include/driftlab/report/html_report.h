// HTML report of a Monte-Carlo result: one self-contained file (CSS, the embedded plotting library
// and the plot data inline; nothing loaded), readable offline and attachable to a design review or
// a CI artifact. The plots are interactive (zoom, pan, cursor values, log/linear, series toggles,
// PNG export; clients/report/src/interactive_plot.h).
//
// Contents: the job's name and description; first screen: CEP50/CEP95 at the final epoch with
// their 95 % intervals (order statistics of the runs' horizontal errors) and the final sigma of
// position, velocity and attitude with theirs, what was simulated (motion length, distance and top
// speed regenerated from the job echo, IMU model figures in datasheet units, mechanization, aiding,
// filter, runs), the true trajectory north against east, the consistency verdict (filter or
// covariance analysis); the summary table of the final epoch (mean, sigma and RMS with their 95 %
// confidence intervals, percentiles of |error|, CEP50/CEP95/2DRMS; one fixed-point format per row)
// and, collapsed, a percentile table per further checkpoint; error envelopes against time per
// component (mean +- sigma band, +-RMS, the prediction when present) with GNSS outages and ZUPT
// periods shaded; the NEES plot; the final horizontal scatter (east vs north per run, with the
// CEP50 and CEP95 circles; hovering a point shows its run index and the `driftlab simulate --run`
// command that regenerates it); histograms of the final horizontal error and of every other
// component; run facts (engine version, timings); the job echo as JSON, collapsed. All text from
// the result is HTML-escaped. Angles in degrees, other units SI, as in the result.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

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

}  // namespace driftlab::app
