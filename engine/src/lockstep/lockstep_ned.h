// Lockstep runner of the free-inertial NED Monte-Carlo path: W runs advance together, their state
// stored as structure of arrays across runs (lanes). Internal to the engine. This folder holds only
// what runs W lanes; the physics it runs is written once over the lane width in its concern's
// folder (sensors/triad_step.h, ins/ned_step.h, earth/earth_lanes.h, stats/nav_error_lanes.h).
//
// Split:
//  * LockstepJob: the job constants, composed once per job (sensor model incl. the flicker design
//    and the per-sample step coefficients, Earth model, mechanization options), flat.
//  * LockstepGroup: the run state of up to kMaxLanes runs, [component][lane] arrays: per-run
//    sensor constants and states, the deviates of the current block, the navigation state.
//  * The lane kernel (lockstep_ned_kernel.h), one copy per instruction set
//    (lockstep_ned_{baseline,avx2,avx512}.cc), advances a group over a range of samples: sensor
//    error step, then the mechanization step (or, in the alignment window, the sums of the measured
//    increments).
//
// Same bits as the scalar code: the scalar code runs the same steps at W = 1
// (TriadErrorSimulator::ApplyIncrement, sensors.cc; NedMechanization::Update, ins.cc), lane-wise
// IEEE operations in Eigen 3.4's order for quaternion products, rotation of vectors and norms
// (math/vector_lanes.h), sin and cos being the engine's own (math/elementary_functions.h);
// -ffp-contract=off everywhere. Deviates come from the same RandomStream keys and indices. So a
// run's result is the same whichever lane, group, thread, shard or instruction set computes it,
// and equal to the scalar RunNed's (lockstep_ned_test.cc checks all of this). (The equality
// between lockstep paths holds for any build; the equality with RunNed's Eigen code elsewhere in
// the run assumes Eigen's operation order of the default x86-64 / arm64 build, which a build with
// wider Eigen packets, e.g. -march=native with AVX, could change.)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "driftlab/ins.h"
#include "driftlab/nav_state.h"
#include "driftlab/random.h"
#include "driftlab/sensor_params.h"
#include "driftlab/sensors.h"
#include "lockstep/lockstep_lanes.h"

namespace driftlab::lockstep {

// The instruction-set paths.
enum class Isa { kBaseline = 0, kAvx2 = 1, kAvx512 = 2 };

struct Kernel {
  Isa isa = Isa::kBaseline;
  int width = 2;  // lanes per group
  AdvanceFn advance = nullptr;
  FillLanesFn fill_lanes = nullptr;
  ErrorsFn errors = nullptr;
  const char* name = "baseline";
};

// The kernel for this CPU: the widest the CPU supports, unless DRIFTLAB_ISA (baseline, avx2,
// avx512) forces one; forcing a path the CPU lacks throws SpecError naming the variable.
Kernel SelectKernel();
// DRIFTLAB_ISA=scalar: the one-run-at-a-time reference path (RunNed) instead of the lockstep one.
bool ScalarForced();
// Whether the CPU (and this build) can run `isa`.
bool IsaAvailable(Isa isa);
Kernel KernelFor(Isa isa);

struct LockstepJob {
  KernelJob kernel;
  ImuErrorModel model;
  TriadJobConstants constants[2];
  uint64_t seed = 0;
};

static_assert(sizeof(ImuIncrement) == 6 * sizeof(double), "KernelInputs reads 6 doubles a sample");
static_assert(kMaxFlicker == kMaxFlickerComponents);

// Composes the job constants (validates the model).
LockstepJob ComposeJob(const ImuErrorModel* model, uint64_t seed, const NavEnvironment& env,
                       double rate_hz, const NedMechanizationOptions& options);

// Per-sample streams of a triad: the independent part, the GM drive, the walk's step.
inline constexpr int kPerSampleStreams = 3;

// The random streams of a group's runs (kept between blocks).
struct GroupStreams {
  // [triad][stream: independent (kWhiteNoise), gm_w1, rw_w1][axis][lane]
  RandomStream per_sample[2][kPerSampleStreams][3][kMaxLanes];
  // [triad][axis][component][lane]
  std::vector<RandomStream> flicker;
  RandomStream& Flicker(int triad, int axis, int j, int lane) {
    return flicker[static_cast<size_t>(((triad * 3 + axis) * kMaxFlicker + j) * kMaxLanes + lane)];
  }
  // A window of deviates per flicker stream, filled in one call for all lanes (Kernel::fill_lanes,
  // rows of lanes) and used by the blocks that need them: a component updated every 2^m samples
  // needs only kBlock >> m deviates a block, and small fills cost more in call overhead than in
  // arithmetic. A window covers kFlickerWindow deviates from flicker_window_first (the Philox block
  // holding the first one: up to 3 more rows before it); windows of [triad][component] start at the
  // same deviate index for every axis; StartSensorLane invalidates them (new streams).
  static constexpr int kFlickerWindow = 128;
  static constexpr int kFlickerWindowRows = kFlickerWindow + 4;
  std::vector<double> flicker_window;                  // [triad][component][axis][row][kMaxLanes]
  uint64_t flicker_window_first[2][kMaxFlicker] = {};  // deviate index of row 0 (a multiple of 4)
  int flicker_window_valid[2][kMaxFlicker] = {};
  double (*FlickerWindow(int triad, int j, int axis))[kMaxLanes] {
    return reinterpret_cast<double(*)[kMaxLanes]>(
        flicker_window.data() +
        static_cast<size_t>((triad * kMaxFlicker + j) * 3 + axis) * kFlickerWindowRows * kMaxLanes);
  }
};

// Sets lane `lane` of `group` to run `run`: the sensor's run constants and streams; the
// navigation state is set by SetNavLane.
void StartSensorLane(const LockstepJob& job, uint32_t run, int lane, LockstepGroup* group,
                     GroupStreams* streams);
// Sets lane `lane`'s navigation state to `initial` (as NedMechanization's constructor does) and
// resets the group's step count.
void SetNavLane(const NavState& initial, int lane, LockstepGroup* group);
// Loads the deviates of the block starting at sample k = block_begin (a multiple of kBlock).
void LoadBlock(const LockstepJob& job, const Kernel& kernel, int64_t block_begin,
               GroupStreams* streams, LockstepGroup* group);
// Lane `lane`'s navigation state (NedMechanization::state()).
NavState NavStateOfLane(const LockstepGroup& group, double dt_s, int lane);
// The truth's share of the error components at one epoch (NavErrorTruth: position scaling, Euler
// angles), for Kernel::errors.
nav_error_lanes::TruthTerms ErrorTruthTerms(const NavEnvironment& env, const NavState& truth);

}  // namespace driftlab::lockstep
