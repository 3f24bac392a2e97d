#include "job_validation.h"

#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/spec_error.h"

namespace driftlab::fuzz {

void ValidateParsedJob(const v1::Job& job) {
  const app::JobFile file{job, "/nonexistent/driftlab-fuzz"};
  try {
    app::ValidateJob(file);
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
