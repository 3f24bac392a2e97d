// Result files: a driftlab.v1.JobResult (result.proto) as its protobuf JSON mapping, with proto
// field names, pretty-printed, every scalar printed even when zero (so that readers other than
// protobuf, e.g. Python's json module, find every field). protobuf prints a double with 15
// significant digits when that reads back exactly, else 17 (0.1 stays "0.1", 1/3 becomes
// 0.33333333333333331), so a write followed by a read gives the same bits; -0.0 is written
// "-0.0" (protobuf's own "-0" would read back as +0.0). NaN and infinities are the JSON strings
// "NaN", "Infinity", "-Infinity" of the mapping.
//
// Errors are driftlab::SpecError naming the file, then the field path, value and allowed range:
//   "shard0.json: epochs[3].t_s: 2 is not allowed; allowed: > epochs[2].t_s = 2"
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

// Number of ErrorComponent values that carry data (all but UNSPECIFIED): 11.
inline constexpr int kErrorComponentCount = 11;

// Lower-case name of a component as used in metric names and the report, e.g.
// "horizontal_position_m" for HORIZONTAL_POSITION_M.
std::string ComponentKey(v1::ErrorComponent component);

// Unit of a component for axis labels: "m", "m/s" or "deg".
std::string ComponentUnit(v1::ErrorComponent component);

// Structural checks every reader relies on: run range inside [0, runs), epochs and checkpoints
// present with t_s strictly increasing, the last checkpoint at the final epoch, exactly 11
// components in enum order everywhere, statistics not NaN (means, sigmas, RMS, percentiles
// finite; upper confidence bounds may be +Infinity; with run_count = 1 sigma and its interval are
// NaN, as the engine reports them), sigmas, RMS and percentiles non-negative,
// p50 <= p68 <= p95 <= p99 <= max_abs, per-run values empty or one entry per run of the file.
// Throws SpecError naming the field path (no file name).
void ValidateJobResult(const v1::JobResult& result);

// JSON text of a result (see above). Throws SpecError("result", ...) if protobuf cannot print it.
std::string JobResultToJson(const v1::JobResult& result);

// Parses and validates a result; `source` names the text in errors. Throws SpecError.
v1::JobResult ParseJobResultJson(std::string_view json_text, std::string_view source = "result");

// Reads and validates a result file. Throws SpecError naming the file (missing, unreadable, bad
// JSON, invalid content).
v1::JobResult ReadJobResult(const std::filesystem::path& path);

// Validates `result` and writes it to `path` (replacing the file). Throws SpecError naming the
// file when it is invalid or cannot be written.
void WriteJobResult(const std::filesystem::path& path, const v1::JobResult& result);

}  // namespace driftlab::app
