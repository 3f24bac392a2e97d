// The `driftlab` commands, one file each; main.cc parses the command line and dispatches here.
#pragma once

#include <string>

namespace driftlab::cli {

// Exit statuses shared by every command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // I/O or internal error
inline constexpr int kExitBadJob = 2;   // invalid job file or command line

// `driftlab validate JOB`: prints "OK" or the first error of the job.
int RunValidate(const std::string& job_path);

// `driftlab simulate JOB --out DIR`: error-free simulation of the job's motion through its
// mechanization; writes truth.csv, imu.csv, nav.csv, errors.csv to DIR and prints a summary. The
// job is validated completely before DIR is created.
int RunSimulate(const std::string& job_path, const std::string& out_dir);

}  // namespace driftlab::cli
