#include <fmt/format.h>

#include <cstdio>

#include "commands.h"
#include "driftlab/jobspec/job_file.h"
#include "driftlab/jobspec/translate.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {

int RunValidate(const std::string& job_path) {
  try {
    jobspec::ValidateJob(jobspec::LoadJobFile(job_path));
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  fmt::print("OK\n");
  return kExitOk;
}

}  // namespace driftlab::cli
