// What `driftlab run` prints and writes for a Monte-Carlo result, shared by the in-process run,
// `merge`, `run --server` and `result` (defined in run_command.cc), so that a result fetched
// from a server is written exactly as a local one.
#pragma once

#include <optional>
#include <string>

#include "driftlab/v1/result.pb.h"

namespace driftlab::cli {

// Prints the final-epoch summary of a Monte-Carlo result to stdout (runs, seed, per-component
// mean/std/RMS with the std's 95 % interval, CEP50/CEP95/2DRMS, timings).
void PrintFinalSummary(const v1::JobResult& result);

// Writes the result file (app::WriteJobResult) and, when given, the HTML report, creating
// their directories. Throws SpecError naming the file on a write error.
void WriteOutputs(const v1::JobResult& result, const std::string& out,
                  const std::optional<std::string>& report);

// PrintFinalSummary and WriteOutputs; returns the exit status (kExitOk, or kExitFailure with the
// error on stderr).
int PrintAndWriteOutputs(const v1::JobResult& result, const std::string& out,
                         const std::optional<std::string>& report);

}  // namespace driftlab::cli
