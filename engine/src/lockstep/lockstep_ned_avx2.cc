// The lockstep NED lane kernel (lockstep_ned_kernel.h) for AVX2 (compiled with -mavx2, no
// FMA), 4 lanes per group.
// engine/CMakeLists.txt gives this file its instruction-set options; it includes no header that
// defines inline code shared with other files (lockstep_lanes.h).
#include "lockstep/lockstep_ned_kernel.h"

namespace driftlab::lockstep {

#if defined(__AVX2__)
namespace {
void Advance4(const KernelJob& job, const KernelInputs& in, int64_t k_begin, int64_t k_end,
              bool navigate, LockstepGroup* group) {
  Kernel<4>::Advance(job, in, k_begin, k_end, navigate, group);
}
void FillLanes(const uint32_t* key, const uint32_t* run_words, uint32_t stream_word,
               uint64_t block0, int nblocks, double (*out)[kMaxLanes]) {
  random_kernels::GaussianAcrossRuns<4, 4, kMaxLanes>(key, run_words, stream_word, block0, nblocks,
                                                      &out[0][0]);
}
void Errors(const nav_error_lanes::TruthTerms& truth, const NavLanes& nav,
            double (*out)[kMaxLanes]) {
  Kernel<4>::Errors(truth, nav, out);
}
}  // namespace

KernelEntry EntryAvx2() { return {&Advance4, &FillLanes, &Errors}; }
#else
KernelEntry EntryAvx2() { return {}; }
#endif

}  // namespace driftlab::lockstep
