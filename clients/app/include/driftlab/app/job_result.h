// The engine's Monte-Carlo statistics as the result schema (driftlab.v1.JobResult, result.proto)
// and back for `driftlab merge`.
//
// Units: the engine's statistics are SI with angles in radians; the result file has angles in
// degrees (API rule). The exact sums of the merge state stay in the engine's units (radians for
// angles): they are the engine's opaque state, converted only through the engine. Checkpoint
// per-run values are converted per value, and every checkpoint summary (percentiles, CEP, 2DRMS,
// maxima) is computed from those converted values in run order, by FillCheckpointSummaries, in
// both `run` and `merge`: so a merged result equals the single-process one bit for bit.
#pragma once

#include <string>
#include <vector>

#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

// The result of a (shard of a) job. `cpu_s` is the process CPU time when measured (< 0: absent).
// Throws SpecError for a cancelled job or runs that are not one contiguous range, and for a
// statistic that is not finite (CheckResultStatistics): such a result is never written or stored
// as a success.
v1::JobResult ToJobResult(const v1::Job& job_as_run, const MonteCarloStatistics& statistics,
                          const std::string& engine_version, double cpu_s = -1.0);
// The same with the analyses of RunMonteCarloWithAnalysis: `covariance` (predicted sigma per
// epoch, in the result's units and component order) and `filter_consistency` (average NEES per
// epoch with its chi-square 95 % bounds; its exact sums go to merge_state for `merge`).
v1::JobResult ToJobResult(const v1::Job& job_as_run, const MonteCarloOutput& output,
                          const std::string& engine_version, double cpu_s = -1.0);

// The last check before a result is written (`run`, `merge`) or stored (the server): every
// statistic the result holds finite (epochs, checkpoint summaries and per-run values, whichever
// are present: a shard's partial statistics pass; the sample sigma and its interval may be NaN
// for one run, result.proto), every predicted sigma of the covariance analysis finite and >= 0,
// every average NEES and its bounds finite. The result's structure is ValidateJobResult's
// (result_file.h). Throws SpecError("result", "<path>: nan is not allowed; ...").
void CheckResultStatistics(const v1::JobResult& result);

// Fills each checkpoint's percentiles, CEP50/95, 2DRMS and maxima from its per-run values.
void FillCheckpointSummaries(v1::JobResult* result);

// The engine statistics held by a result (epoch sums from the merge state, checkpoint values
// converted back to radians); throws SpecError naming `source` for a result without a usable
// merge state.
MonteCarloStatistics StatisticsFromJobResult(const v1::JobResult& result,
                                             const std::string& source);

// `out`'s filter_consistency (and merge-state NEES sums) computed from `result`'s merge-state NEES
// sums and counts, as ToJobResult writes them. Throws SpecError naming `source`.
void SetFilterConsistencyFromSums(const v1::JobResult& result, const std::string& source,
                                  v1::JobResult* out);

// Merges shards of one job (any order, any grouping) into one result: the same job echo, seed
// and epochs are required and the runs must be disjoint and together contiguous. `sources` name
// the inputs in errors. Throws SpecError.
v1::JobResult MergeJobResults(const std::vector<v1::JobResult>& shards,
                              const std::vector<std::string>& sources,
                              const std::string& engine_version);

}  // namespace driftlab::app
