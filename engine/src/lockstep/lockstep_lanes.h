// Plain-data types shared by the lockstep host code (lockstep_ned.cc) and the lane kernels
// (lockstep_ned_kernel.h): no Eigen, no standard-library templates, so that the kernel files,
// compiled for different instruction sets, share no inline code with the rest of the engine
// (an inline function emitted by an AVX-512 file could otherwise be picked by the linker for all).
#pragma once

#include <cstdint>

#include "driftlab/earth_constants.h"
#include "driftlab/triad_step_params.h"
#include "stats/nav_error_lanes.h"

namespace driftlab::lockstep {

inline constexpr int kMaxLanes = 8;
// Samples per refill of the per-sample deviate buffers (aligned to multiples of the step index);
// 128 rather than 32 lets the deviate loops run 32 Philox blocks per call (fewer, longer calls).
inline constexpr int kBlock = 128;
inline constexpr int kMaxFlicker = kTriadStepMaxFlicker;  // kMaxFlickerComponents (sensors.h)

// Job constants of one triad (TriadJobConstants, flattened for the kernel; TriadStepParamsOf).
using TriadParams = ::driftlab::TriadStepParams;

// What the kernel reads of the job.
struct KernelJob {
  int has_sensor = 0;
  TriadParams triad[2];  // 0 = gyro, 1 = accel
  int g_sensitivity = 0;
  double gyro_g_sensitivity[3][3] = {};
  EarthParams earth;  // NavEnvironment::params()
  double dt_s = 0.0;
  int coning_sculling = 1;
  int truth_height = 0;
};

// Run state of one triad for up to kMaxLanes runs; x[...][lane].
struct TriadLanes {
  double scale_misalignment[3][3][kMaxLanes];
  double constant_bias[3][kMaxLanes];
  double gm_state[3][kMaxLanes];
  double rw_state[3][kMaxLanes];
  double remainder[3][kMaxLanes];
  double flicker_state[3][kMaxFlicker][kMaxLanes];
  // Deviates of the current block: per-sample terms at [axis][k mod kBlock][lane]; flicker
  // component j at [axis][j][(k - block start) >> period_log2[j]][lane].
  double independent[3][kBlock][kMaxLanes];  // TriadJobConstants::independent_sigma's deviate
  double gm_w1[3][kBlock][kMaxLanes];
  double rw_w1[3][kBlock][kMaxLanes];
  double flicker_w[3][kMaxFlicker][kBlock][kMaxLanes];
};

// Navigation state (NedMechanization's) for up to kMaxLanes runs.
struct NavLanes {
  double lat_rad[kMaxLanes], lon_rad[kMaxLanes], h_m[kMaxLanes];
  double v_eb_n[3][kMaxLanes];
  double q_b_n[4][kMaxLanes];  // w, x, y, z
  double previous_dtheta[3][kMaxLanes], previous_dv[3][kMaxLanes];
  double previous_v_eb_n[3][kMaxLanes];
  // Alignment window: sums of the measured increments.
  double sum_dtheta[3][kMaxLanes], sum_dv[3][kMaxLanes];
  int have_previous = 0;
  int64_t steps = 0;
  double t0_s = 0.0;
};

struct LockstepGroup {
  TriadLanes triad[2];
  NavLanes nav;
  int lanes = 0;  // runs in use (<= the kernel's width)
};

// Shared inputs of a kernel call: ideal increments k = 0..n (ImuIncrement: delta_theta_ib_b then
// delta_v_ib_b, 6 doubles each) and,
// with a truth-height vertical channel, the truth h and v_D at every sample.
struct KernelInputs {
  const double* increments = nullptr;
  const double* h_m = nullptr;
  const double* v_D_m_per_s = nullptr;
};

// Advances `group` over samples k in [k_begin, k_end), all inside one deviate block
// (k_begin / kBlock == (k_end - 1) / kBlock) whose deviates are loaded. navigate = false: the
// alignment window (sums of the measured increments); true: the mechanization step.
using AdvanceFn = void (*)(const KernelJob& job, const KernelInputs& in, int64_t k_begin,
                           int64_t k_end, bool navigate, LockstepGroup* group);

// N(0, 1) deviates of the streams (key[2], run_words[lane], stream_word) of the kernel's lanes
// (its width: 4 or 8), blocks [block0, block0 + nblocks): deviate 4 b + i of lane l into
// out[4 (b - block0) + i][l] (random_kernels::GaussianAcrossRuns built for the kernel's
// instruction set: the numbers of RandomStream::FillGaussian).
using FillLanesFn = void (*)(const uint32_t* key, const uint32_t* run_words, uint32_t stream_word,
                             uint64_t block0, int nblocks, double (*out)[kMaxLanes]);

// The error components (nav_error_lanes::ErrorComponents, in ErrorComponent order) of all the
// kernel's lanes of `nav` against one truth: component c of lane l into out[c][l].
using ErrorsFn = void (*)(const nav_error_lanes::TruthTerms& truth, const NavLanes& nav,
                          double (*out)[kMaxLanes]);

struct KernelEntry {
  AdvanceFn advance = nullptr;
  FillLanesFn fill_lanes = nullptr;
  ErrorsFn errors = nullptr;
};

// Per-ISA entry points (defined in lockstep_ned_<isa>.cc; null where the build or the
// architecture has no such path).
KernelEntry EntryBaseline();
KernelEntry EntryAvx2();
KernelEntry EntryAvx512();

}  // namespace driftlab::lockstep
