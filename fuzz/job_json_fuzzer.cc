// Fuzz target: job files in JSON (fuzz_targets.h).
#include "driftlab/app/job_file.h"
#include "driftlab/spec_error.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"
#include "job_validation.h"

namespace driftlab::fuzz {

void FuzzJobJson(const uint8_t* data, size_t size) {
  v1::Job job;
  try {
    job = app::ParseJobJson(AsText(data, size), "fuzz.json");
  } catch (const SpecError&) {
    return;
  }
  ValidateParsedJob(job);
}

}  // namespace driftlab::fuzz
