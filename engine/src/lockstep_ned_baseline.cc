// The lockstep NED lane kernel (lockstep_ned_kernel.h) for the baseline instruction set (x86-64
// SSE2, or any other architecture), 4 lanes per group.
// engine/CMakeLists.txt gives this file its instruction-set options; it includes no header that
// defines inline code shared with other files (lockstep_lanes.h).
#include "lockstep_ned_kernel.h"

namespace driftlab::lockstep {

namespace {
void Advance4(const KernelJob& job, const KernelInputs& in, int64_t k_begin, int64_t k_end,
              bool navigate, LockstepGroup* group) {
  Kernel<4>::Advance(job, in, k_begin, k_end, navigate, group);
}
}  // namespace

AdvanceFn AdvanceBaseline() { return &Advance4; }

}  // namespace driftlab::lockstep
