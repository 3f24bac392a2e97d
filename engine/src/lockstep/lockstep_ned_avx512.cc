// The lockstep NED lane kernel (lockstep_ned_kernel.h) for AVX-512 (compiled with -mavx512f
// -mavx512dq -mavx512vl, no FMA), 8 lanes per group.
// engine/CMakeLists.txt gives this file its instruction-set options; it includes no header that
// defines inline code shared with other files (lockstep_lanes.h).
#include "lockstep/lockstep_ned_kernel.h"

namespace driftlab::lockstep {

#if defined(__AVX512F__)
namespace {
void Advance8(const KernelJob& job, const KernelInputs& in, int64_t k_begin, int64_t k_end,
              bool navigate, LockstepGroup* group) {
  Kernel<8>::Advance(job, in, k_begin, k_end, navigate, group);
}
void FillLanes(const uint32_t* key, const uint32_t* run_words, uint32_t stream_word,
               uint64_t block0, int nblocks, double (*out)[kMaxLanes]) {
  random_kernels::GaussianAcrossRuns<8, 8, kMaxLanes>(key, run_words, stream_word, block0, nblocks,
                                                      &out[0][0]);
}
void Errors(const nav_error_lanes::TruthTerms& truth, const NavLanes& nav,
            double (*out)[kMaxLanes]) {
  Kernel<8>::Errors(truth, nav, out);
}
}  // namespace

KernelEntry EntryAvx512() { return {&Advance8, &FillLanes, &Errors}; }
#else
KernelEntry EntryAvx512() { return {}; }
#endif

}  // namespace driftlab::lockstep
