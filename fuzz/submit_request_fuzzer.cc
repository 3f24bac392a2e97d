// Fuzz target: the server's Submit (fuzz_targets.h). The input is the binary request as it arrives
// over gRPC: parsed as a SubmitJobRequest (a malformed message is refused before validation),
// then validated by ValidateSubmitRequest, the server's own check of every submitted job, with
// the server's default limits.
#include "driftlab/monte_carlo.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/spec_error.h"
#include "driftlab/v1/service.pb.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzSubmitRequest(const uint8_t* data, size_t size) {
  v1::SubmitJobRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return;
  try {
    server::ValidateSubmitRequest(request, /*threads_per_job=*/1, kDefaultMaxJobMemoryBytes);
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
