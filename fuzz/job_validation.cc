#include "job_validation.h"

#include "driftlab/jobspec/job_file.h"
#include "driftlab/jobspec/monte_carlo_job.h"
#include "driftlab/jobspec/translate.h"
#include "driftlab/spec_error.h"

namespace driftlab::fuzz {

void ValidateParsedJob(const v1::Job& job) {
  const jobspec::JobFile file{job, "/nonexistent/driftlab-fuzz"};
  try {
    jobspec::ValidateJob(file);
  } catch (const SpecError&) {
    return;
  }
  try {
    jobspec::ToMonteCarloSpec(file, jobspec::MonteCarloOverrides{});
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
