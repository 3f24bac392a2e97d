// Translation of a driftlab.v1.Job into the engine's types, with validation of every field.
//
// Shared by the CLI and the gRPC server, so both report the same errors. Angles are
// degrees in the API and radians in the engine; every other unit passes through unchanged. Every
// numeric field is checked for NaN/infinity and for its allowed range; required fields are
// reported as missing; combinations (exactly one of two alternatives) are checked. Errors are
// driftlab::SpecError with the proto field path, the value and the allowed range:
//   "motion.segments[1].static.duration_s: -5 is not allowed; allowed: 0 < duration_s <= 100000 s"
#pragma once

#include <filesystem>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/output_files.h"
#include "driftlab/simulate.h"
#include "driftlab/v1/job.pb.h"

namespace driftlab::app {

// Field-by-field translation and validation. Imported motion files named by the job are read
// here; relative paths resolve against base_dir. Throws SpecError.
SimulationSpec ToSimulationSpec(const v1::Job& job, const std::filesystem::path& base_dir);

// The whole job's validation is ValidateJob (job_validator.h), which every entry calls.

// The files a job reads besides the job file: its motion file (motion.gnss_ins_sim_file.path or
// motion.truth_profile_file.path, resolved against base_dir as the translation resolves it), each
// with its field path; empty for a motion of segments. For the commands' output checks.
std::vector<CommandPath> JobInputFiles(const v1::Job& job, const std::filesystem::path& base_dir);

}  // namespace driftlab::app
