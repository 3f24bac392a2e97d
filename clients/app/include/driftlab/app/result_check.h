// A result's statistics checked against the data they summarise, before a tool uses them (the
// gate, merge, the report): a file whose summaries were edited, or whose exact sums disagree with
// its own statistics, is refused instead of being gated, merged or reported.
//
// Checked, each where the file holds the data (result.proto):
//   * every epoch's mean, std, rms and their 95 % intervals against the exact sums of
//     merge_state (the engine's own summary of those sums, in the result's units);
//   * every checkpoint's percentiles, maxima, CEP50/95 and 2DRMS against its per-run values;
//   * at a checkpoint that is also an epoch, the epoch's mean, std and rms against the per-run
//     values;
//   * the filter's average NEES per epoch against merge_state's NEES sums and counts.
// Equal means equal to kResultCheckRelTol relative (the writer computes them with the same
// operations; the tolerance admits a file whose summaries another build rounded differently in the
// last bits, never an edit that changes a decision). NaN must match NaN (sigma of one run).
// Throws SpecError naming `source`, the field path, the value and the value the data give.
#pragma once

#include <string>

#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

inline constexpr double kResultCheckRelTol = 1e-9;

// Checks a structurally valid result (ValidateJobResult).
void VerifyResultStatistics(const v1::JobResult& result, const std::string& source);

}  // namespace driftlab::app
