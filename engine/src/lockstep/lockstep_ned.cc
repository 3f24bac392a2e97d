// Host side of the lockstep NED runner (lockstep_ned.h): job composition, lane set-up, deviate
// blocks, instruction-set dispatch.
#include "lockstep/lockstep_ned.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab::lockstep {
namespace {

constexpr ErrorTerm kPerSampleTerms[kPerSampleStreams] = {
    ErrorTerm::kWhiteNoise, ErrorTerm::kGaussMarkov, ErrorTerm::kRandomWalk};

bool TermOn(const TriadParams& p, int term) {
  switch (term) {
    case 0:
      return p.independent != 0;
    case 1:
      return p.gauss_markov != 0;
    default:
      return p.random_walk != 0;
  }
}

double (*PerSampleBuffer(TriadLanes& t, int term))[kBlock][kMaxLanes] {
  switch (term) {
    case 0:
      return t.independent;
    case 1:
      return t.gm_w1;
    default:
      return t.rw_w1;
  }
}

}  // namespace

LockstepJob ComposeJob(const ImuErrorModel* model, uint64_t seed, const NavEnvironment& env,
                       double rate_hz, const NedMechanizationOptions& options) {
  LockstepJob job;
  job.seed = seed;
  KernelJob& k = job.kernel;
  k.dt_s = 1.0 / rate_hz;
  k.coning_sculling = options.coning_sculling;
  k.truth_height = options.vertical == VerticalChannel::kTruthHeight;
  k.earth = env.params();
  if (model != nullptr) {
    ValidateImuErrorModel(*model, "sensor");
    job.model = *model;
    k.has_sensor = 1;
    job.constants[0] = ComposeTriadJobConstants(model->gyro, rate_hz, "sensor.gyro");
    job.constants[1] = ComposeTriadJobConstants(model->accel, rate_hz, "sensor.accel");
    for (int t = 0; t < 2; ++t) k.triad[t] = TriadStepParamsOf(job.constants[t]);
    k.g_sensitivity = !model->gyro_g_sensitivity.isZero(0.0);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) k.gyro_g_sensitivity[r][c] = model->gyro_g_sensitivity(r, c);
    }
  }
  return job;
}

void StartSensorLane(const LockstepJob& job, uint32_t run, int lane, LockstepGroup* group,
                     GroupStreams* streams) {
  if (!job.kernel.has_sensor) return;
  if (streams->flicker.empty()) {
    streams->flicker.resize(static_cast<size_t>(2 * 3 * kMaxFlicker * kMaxLanes));
  }
  for (int t = 0; t < 2; ++t) {
    for (int j = 0; j < kMaxFlicker; ++j) streams->flicker_window_valid[t][j] = 0;
  }
  for (int t = 0; t < 2; ++t) {
    const SensorId sensor = t == 0 ? SensorId::kGyro : SensorId::kAccel;
    const TriadErrorParams& params = t == 0 ? job.model.gyro : job.model.accel;
    const TriadRunConstants rc =
        DrawTriadRunConstants(params, job.constants[t], sensor, job.seed, run);
    TriadLanes& lanes = group->triad[t];
    for (int i = 0; i < 3; ++i) {
      for (int c = 0; c < 3; ++c)
        lanes.scale_misalignment[i][c][lane] = rc.scale_misalignment(i, c);
      lanes.constant_bias[i][lane] = rc.constant_bias[i];
      lanes.gm_state[i][lane] = rc.gm_state[static_cast<size_t>(i)];
      lanes.rw_state[i][lane] = 0.0;
      lanes.remainder[i][lane] = 0.0;
      for (int j = 0; j < kMaxFlicker; ++j) {
        lanes.flicker_state[i][j][lane] =
            rc.flicker_state[static_cast<size_t>(i)][static_cast<size_t>(j)];
      }
    }
    const TriadParams& p = job.kernel.triad[t];
    for (int term = 0; term < kPerSampleStreams; ++term) {
      if (!TermOn(p, term)) continue;
      for (int axis = 0; axis < 3; ++axis) {
        streams->per_sample[t][term][axis][lane] = RandomStream(
            job.seed, run, StreamKey{sensor, static_cast<uint8_t>(axis), kPerSampleTerms[term], 0});
      }
    }
    for (int axis = 0; axis < 3; ++axis) {
      for (int j = 0; j < p.n_flicker; ++j) {
        streams->Flicker(t, axis, j, lane) =
            RandomStream(job.seed, run,
                         StreamKey{sensor, static_cast<uint8_t>(axis), ErrorTerm::kFlicker,
                                   static_cast<uint8_t>(j)});
      }
    }
  }
}

void SetNavLane(const NavState& initial, int lane, LockstepGroup* group) {
  NavLanes& n = group->nav;
  Quaterniond q = initial.q_b_n;
  q.normalize();  // as NedMechanization's constructor
  n.lat_rad[lane] = initial.llh.lat_rad;
  n.lon_rad[lane] = initial.llh.lon_rad;
  n.h_m[lane] = initial.llh.h_m;
  n.q_b_n[0][lane] = q.w();
  n.q_b_n[1][lane] = q.x();
  n.q_b_n[2][lane] = q.y();
  n.q_b_n[3][lane] = q.z();
  for (int i = 0; i < 3; ++i) {
    n.v_eb_n[i][lane] = initial.v_eb_n[i];
    n.previous_v_eb_n[i][lane] = initial.v_eb_n[i];
    n.previous_dtheta[i][lane] = 0.0;
    n.previous_dv[i][lane] = 0.0;
  }
  n.have_previous = 0;
  n.steps = 0;
  n.t0_s = initial.t_s;
}

namespace {

// The run words of the streams r[0 .. kMaxLanes) of a group's lanes for Kernel::fill_lanes:
// they differ only in their run word (same seed, same stream); lanes past `lanes` repeat lane 0's
// (their numbers are not used).
void LaneRunWords(const RandomStream* r, int lanes, uint32_t (&run_words)[kMaxLanes]) {
  for (int lane = 0; lane < kMaxLanes; ++lane) {
    const RandomStream& rl = r[lane < lanes ? lane : 0];
    if (rl.key() != r[0].key() || rl.stream_word() != r[0].stream_word()) {
      throw std::logic_error("lockstep: the lanes of a group draw from different streams");
    }
    run_words[lane] = rl.run_word();
  }
}

}  // namespace

void LoadBlock(const LockstepJob& job, const Kernel& kernel, int64_t block_begin,
               GroupStreams* streams, LockstepGroup* group) {
  if (!job.kernel.has_sensor) return;
  const uint64_t b0 = static_cast<uint64_t>(block_begin);
  static_assert(kBlock % 4 == 0, "blocks start at a Philox block");
  for (int t = 0; t < 2; ++t) {
    const TriadParams& p = job.kernel.triad[t];
    TriadLanes& lanes = group->triad[t];
    for (int term = 0; term < kPerSampleStreams; ++term) {
      if (!TermOn(p, term)) continue;
      double(*dst)[kBlock][kMaxLanes] = PerSampleBuffer(lanes, term);
      for (int axis = 0; axis < 3; ++axis) {
        const RandomStream* r = streams->per_sample[t][term][axis];
        uint32_t run_words[kMaxLanes];
        LaneRunWords(r, group->lanes, run_words);
        kernel.fill_lanes(r[0].key().data(), run_words, r[0].stream_word(), b0 / 4, kBlock / 4,
                          dst[axis]);
      }
    }
    // Flicker component j advances at steps d = 2^m, 2 * 2^m, ... with deviate (d >> m) - 1.
    for (int j = 0; j < p.n_flicker; ++j) {
      const int m = p.flicker_period_log2[j];
      const uint64_t period = uint64_t{1} << m;
      const uint64_t first_update = (b0 + period - 1) & ~(period - 1);  // first multiple >= b0
      if (first_update >= b0 + kBlock) continue;
      const uint64_t from = first_update == 0 ? period : first_update;
      if (from >= b0 + kBlock) continue;
      const size_t count = static_cast<size_t>((b0 + kBlock - from + period - 1) >> m);
      // Deviates [first, first + count) of the component's streams, from its window.
      const uint64_t first = (from >> m) - 1;
      constexpr int kWindow = GroupStreams::kFlickerWindow;
      constexpr int kRows = GroupStreams::kFlickerWindowRows;
      static_assert(kWindow >= kBlock, "a window holds at least one block's deviates");
      uint64_t& window_first = streams->flicker_window_first[t][j];
      int& valid = streams->flicker_window_valid[t][j];
      if (!valid || first < window_first || first + count > window_first + kRows) {
        if (streams->flicker_window.empty()) {
          streams->flicker_window.resize(static_cast<size_t>(2 * kMaxFlicker * 3 * kRows) *
                                         kMaxLanes);
        }
        window_first = first & ~uint64_t{3};  // the Philox block of deviate `first`
        for (int axis = 0; axis < 3; ++axis) {
          const RandomStream* r = &streams->Flicker(t, axis, j, 0);
          uint32_t run_words[kMaxLanes];
          LaneRunWords(r, group->lanes, run_words);
          kernel.fill_lanes(r[0].key().data(), run_words, r[0].stream_word(), window_first / 4,
                            kRows / 4, streams->FlickerWindow(t, j, axis));
        }
        valid = 1;
      }
      const size_t offset = static_cast<size_t>(first - window_first);
      for (int axis = 0; axis < 3; ++axis) {
        const double(*w)[kMaxLanes] = streams->FlickerWindow(t, j, axis) + offset;
        for (size_t c = 0; c < count; ++c) {
          __builtin_memcpy(lanes.flicker_w[axis][j][((from - b0) >> m) + c], w[c],
                           sizeof(double) * kMaxLanes);
        }
      }
    }
  }
}

NavState NavStateOfLane(const LockstepGroup& group, double dt_s, int lane) {
  const NavLanes& n = group.nav;
  NavState s;
  s.t_s = n.t0_s + static_cast<double>(n.steps) * dt_s;
  s.llh.lat_rad = n.lat_rad[lane];
  s.llh.lon_rad = n.lon_rad[lane];
  s.llh.h_m = n.h_m[lane];
  s.v_eb_n = Vector3d(n.v_eb_n[0][lane], n.v_eb_n[1][lane], n.v_eb_n[2][lane]);
  s.q_b_n = Quaterniond(n.q_b_n[0][lane], n.q_b_n[1][lane], n.q_b_n[2][lane], n.q_b_n[3][lane]);
  return s;
}

nav_error_lanes::TruthTerms ErrorTruthTerms(const NavEnvironment& env, const NavState& truth) {
  const NavErrorTruth t(env, truth);
  nav_error_lanes::TruthTerms terms{};
  terms.lat_rad = t.llh.lat_rad;
  terms.lon_rad = t.llh.lon_rad;
  terms.h_m = t.llh.h_m;
  for (int i = 0; i < 3; ++i) terms.v_eb_n[i] = t.v_eb_n[i];
  terms.north_m = t.position_scale.north_m;
  terms.east_m = t.position_scale.east_m;
  terms.cos_L = t.position_scale.cos_L;
  terms.euler_rad[0] = t.euler.roll_rad;
  terms.euler_rad[1] = t.euler.pitch_rad;
  terms.euler_rad[2] = t.euler.yaw_rad;
  return terms;
}

bool IsaAvailable(Isa isa) {
  switch (isa) {
    case Isa::kBaseline:
      return true;
    case Isa::kAvx2:
#if defined(__x86_64__)
      return EntryAvx2().advance != nullptr && __builtin_cpu_supports("avx2");
#else
      return false;
#endif
    case Isa::kAvx512:
#if defined(__x86_64__)
      return EntryAvx512().advance != nullptr && __builtin_cpu_supports("avx512f") &&
             __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
      return false;
#endif
  }
  return false;
}

Kernel KernelFor(Isa isa) {
  Kernel k;
  k.isa = isa;
  KernelEntry entry;
  switch (isa) {
    case Isa::kBaseline:
      k.width = 4;
      entry = EntryBaseline();
      k.name = "baseline";
      break;
    case Isa::kAvx2:
      k.width = 4;
      entry = EntryAvx2();
      k.name = "avx2";
      break;
    case Isa::kAvx512:
      k.width = 8;
      entry = EntryAvx512();
      k.name = "avx512";
      break;
  }
  k.advance = entry.advance;
  k.fill_lanes = entry.fill_lanes;
  k.errors = entry.errors;
  return k;
}

bool ScalarForced() {
  const char* forced = std::getenv("DRIFTLAB_ISA");
  return forced != nullptr && std::string(forced) == "scalar";
}

Kernel SelectKernel() {
  const char* forced = std::getenv("DRIFTLAB_ISA");
  if (forced != nullptr && *forced != '\0') {
    const std::string name = forced;
    Isa isa = Isa::kBaseline;
    if (name == "baseline") {
      isa = Isa::kBaseline;
    } else if (name == "avx2") {
      isa = Isa::kAvx2;
    } else if (name == "avx512") {
      isa = Isa::kAvx512;
    } else {
      throw SpecError("DRIFTLAB_ISA", name,
                      "scalar, baseline, avx2 or avx512 (or unset: the best the CPU has)");
    }
    if (!IsaAvailable(isa)) {
      throw SpecError("DRIFTLAB_ISA", name,
                      "an instruction set this CPU and build support (baseline always)");
    }
    return KernelFor(isa);
  }
  if (IsaAvailable(Isa::kAvx512)) return KernelFor(Isa::kAvx512);
  if (IsaAvailable(Isa::kAvx2)) return KernelFor(Isa::kAvx2);
  return KernelFor(Isa::kBaseline);
}

}  // namespace driftlab::lockstep
