// The engine's lane code on its own (no Eigen, no oneTBB), built for the machine and, by
// tests/arm64/same_bits.sh, for arm64 (run under qemu-user): it prints digests of what the lane
// code computes, and the script requires the two outputs to be equal line for line (every path
// gives the same bits; DESIGN.md "Same bits everywhere": the engine's own elementary functions,
// lane-wise IEEE arithmetic, no contraction).
// What it runs, at the baseline kernel's width (4 lanes: two SSE2 registers a value on x86-64,
// two NEON registers on arm64):
//   * elementary::Log, SinCos, SinCosNear on a grid of arguments;
//   * the deviates of the lockstep kernels (random_kernels::GaussianAcrossRuns: Philox4x32-10 and
//     Box-Muller) for 4 runs;
//   * 40 blocks (5120 samples at 100 Hz) of the lockstep kernel (lockstep_ned_kernel.h): the
//     sensor-error step (sensors/triad_step.h: scale/misalignment, bias, white noise,
//     Gauss-Markov, random walk, one flicker component, range and quantization) on synthetic
//     increments of a turning, climbing vehicle, then the WGS-84 NED mechanization with
//     coning/sculling (ins/ned_step.h, earth/earth_lanes.h);
//   * the engine's scalar exp, expm1, log, log1p, atan, atan2, asin, acos, hypot and ln Gamma
//     (math/elementary_functions.h, the engine's replacements of the C library's) on grids;
//   * the statistics' error components of the 4 lanes against a truth (nav_error_lanes.h):
//     position, velocity, Euler-angle errors and norms (IEEE operations, the engine's atan2,
//     asin and hypot, and remainder, which is exact in any correct C library).
// Output: one line per check, "name digest" (FNV-1a 64 of the doubles' bytes) and a few values
// in hexadecimal floating point for the reader.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>

#include "lanes/lane.h"
#include "lockstep/lockstep_lanes.h"
#include "lockstep/lockstep_ned_kernel.h"
#include "math/elementary_functions.h"
#include "random/random_kernels.h"
#include "stats/nav_error_lanes.h"

namespace {

using driftlab::lockstep::kBlock;
using driftlab::lockstep::kMaxLanes;
constexpr int kW = 4;

struct Digest {
  uint64_t h = 1469598103934665603ull;
  void Add(double x) {
    unsigned char b[sizeof(double)];
    std::memcpy(b, &x, sizeof(x));
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  }
};

void Print(const char* name, const Digest& d) {
  std::printf("%s %016llx\n", name, static_cast<unsigned long long>(d.h));
}

void ElementaryFunctions() {
  Digest log_d, sincos_d, near_d;
  for (int i = 1; i <= 20000; ++i) {
    const double x = 1e-12 * i * i * i;  // 1e-12 .. 8e0
    log_d.Add(driftlab::elementary::Log<1>(x));
  }
  for (int i = -20000; i <= 20000; ++i) {
    const double x = 1.37e-3 * i * 3.1;  // about -85 .. 85 rad
    double s, c;
    driftlab::elementary::SinCos<1>(x, s, c);
    sincos_d.Add(s);
    sincos_d.Add(c);
    double s4[kW], c4[kW];
    driftlab::lanes::D<kW> xs = {x, x + 1e-3, x - 2e-3, x + 0.02};
    driftlab::lanes::D<kW> x0 = {x, x, x, x};
    driftlab::lanes::D<kW> s0 = {s, s, s, s}, c0 = {c, c, c, c};
    driftlab::lanes::D<kW> so, co;
    driftlab::elementary::SinCosNear<kW>(xs, x0, s0, c0, so, co);
    std::memcpy(s4, &so, sizeof(s4));
    std::memcpy(c4, &co, sizeof(c4));
    for (int l = 0; l < kW; ++l) {
      near_d.Add(s4[l]);
      near_d.Add(c4[l]);
    }
  }
  Print("elementary_log", log_d);
  Print("elementary_sincos", sincos_d);
  Print("elementary_sincos_near", near_d);
  // The scalar functions the engine uses instead of the C library's (driftlab/elementary.h).
  Digest scalar;
  for (int i = -30000; i <= 30000; ++i) {
    const double x = 1.2345e-3 * i + 1e-7;  // about -37 .. 37
    const double t = x / 37.1;              // within (-1, 1)
    using namespace driftlab::elementary;
    scalar.Add(Exp(x * 19.0));
    scalar.Add(Expm1(t));
    scalar.Add(Ln(x * x + 1e-300));
    scalar.Add(Log1p(t));
    scalar.Add(Atan(x));
    scalar.Add(Atan2(x, t - 0.3));
    scalar.Add(Asin(t));
    scalar.Add(Acos(t));
    scalar.Add(Hypot(x, t * 1e200));
    scalar.Add(LgammaPositive(x * x * 10.0 + 1e-3));
  }
  Print("elementary_scalar", scalar);
}

const uint32_t kKey[2] = {0x243f6a88u, 0x85a308d3u};
const uint32_t kRunWords[kMaxLanes] = {0, 1, 2, 1000003, 4, 5, 6, 7};

// Deviates of stream `stream_word` for the 4 runs, Philox blocks [block0, block0 + n), into rows
// of kMaxLanes.
void Fill(uint32_t stream_word, uint64_t block0, int n, double (*rows)[kMaxLanes]) {
  driftlab::random_kernels::GaussianAcrossRuns<2, kW, kMaxLanes>(kKey, kRunWords, stream_word,
                                                                 block0, n, &rows[0][0]);
}

void Deviates() {
  static double rows[4 * 256][kMaxLanes];
  Digest d;
  Fill(7, 123456789012ull, 256, rows);
  for (auto& row : rows) {
    for (int l = 0; l < kW; ++l) d.Add(row[l]);
  }
  Print("deviates", d);
  std::printf("deviate_0_lane_3 %a\n", rows[0][3]);
}

// Job constants of a triad with every term of the step on (values of the order of a tactical
// IMU's at 100 Hz; exact decimal constants, so nothing depends on the C library's exp).
driftlab::TriadStepParams Triad(double scale) {
  driftlab::TriadStepParams p{};
  p.independent = 1;
  p.independent_sigma = 3e-6 * scale;
  p.gauss_markov = 1;
  p.gm_decay = 0.9999;
  p.gm_drive_sigma = 2e-7 * scale;
  p.gm_mean_gain = 0.0099995;
  p.gm_integral_w1_gain = 1e-9 * scale;
  p.random_walk = 1;
  p.rw_step_sigma = 5e-8 * scale;
  p.asymmetry = 1;
  p.half_asymmetry[0] = 1e-4;
  p.half_asymmetry[1] = -2e-4;
  p.half_asymmetry[2] = 5e-5;
  p.n_flicker = 1;
  p.flicker_decay[0] = 0.999;
  p.flicker_drive_sigma[0] = 1e-6 * scale;
  p.flicker_period_log2[0] = 2;
  p.range = 10.0 * scale;
  p.quantization = 1e-7 * scale;
  return p;
}

void KernelAndErrors() {
  using driftlab::elementary::SinCos;
  constexpr double kDt = 0.01;
  constexpr int kBlocks = 40;
  constexpr int64_t kSamples = int64_t{kBlocks} * kBlock;
  driftlab::lockstep::KernelJob job{};
  job.has_sensor = 1;
  job.triad[0] = Triad(1.0);
  job.triad[1] = Triad(100.0);
  job.g_sensitivity = 1;
  job.gyro_g_sensitivity[0][2] = 1e-5;
  job.gyro_g_sensitivity[1][0] = -2e-5;
  job.dt_s = kDt;
  job.coning_sculling = 1;
  // Increments of a vehicle turning at ~0.02 rad/s, pitching and accelerating (body frame).
  static double increments[6 * (kSamples + 1)];
  for (int64_t k = 1; k <= kSamples; ++k) {
    double s1, c1, s2, c2;
    SinCos<1>(0.011 * static_cast<double>(k), s1, c1);
    SinCos<1>(0.0037 * static_cast<double>(k), s2, c2);
    double* in = increments + 6 * k;
    in[0] = kDt * (0.003 * s1);
    in[1] = kDt * (0.002 * c2);
    in[2] = kDt * (0.02 + 0.005 * s2);
    in[3] = kDt * (0.3 * c1);
    in[4] = kDt * (0.1 * s2);
    in[5] = kDt * (-9.80665 + 0.05 * s1);
  }
  auto group = std::make_unique<driftlab::lockstep::LockstepGroup>();
  group->lanes = kW;
  driftlab::lockstep::NavLanes& n = group->nav;
  for (int l = 0; l < kW; ++l) {
    for (int t = 0; t < 2; ++t) {
      driftlab::lockstep::TriadLanes& tr = group->triad[t];
      for (int i = 0; i < 3; ++i) {
        for (int c = 0; c < 3; ++c) tr.scale_misalignment[i][c][l] = i == c ? 1.0 + 1e-4 * l : 2e-5;
        tr.constant_bias[i][l] = (t == 0 ? 1e-6 : 1e-3) * (i + 1 - l);
        tr.gm_state[i][l] = (t == 0 ? 1e-7 : 1e-4) * (l - i);
      }
    }
    n.lat_rad[l] = 0.7853981 + 1e-7 * l;
    n.lon_rad[l] = 3.1415 - 1e-3;  // close to the antimeridian: remainder below is exercised
    n.h_m[l] = 120.0 + l;
    n.v_eb_n[0][l] = 10.0;
    n.v_eb_n[1][l] = 25.0;
    n.v_eb_n[2][l] = -0.5;
    n.q_b_n[0][l] = 0.9238795325112867;  // yaw 45 degrees
    n.q_b_n[3][l] = 0.3826834323650898;
    for (int i = 0; i < 3; ++i) n.previous_v_eb_n[i][l] = n.v_eb_n[i][l];
  }
  driftlab::lockstep::KernelInputs in;
  in.increments = increments;
  for (int b = 0; b < kBlocks; ++b) {
    for (int t = 0; t < 2; ++t) {
      driftlab::lockstep::TriadLanes& tr = group->triad[t];
      for (int axis = 0; axis < 3; ++axis) {
        const uint32_t s = static_cast<uint32_t>(100 * t + 10 * axis);
        const uint64_t block0 = static_cast<uint64_t>(b) * (kBlock / 4);
        Fill(s + 1, block0, kBlock / 4, tr.independent[axis]);
        Fill(s + 2, block0, kBlock / 4, tr.gm_w1[axis]);
        Fill(s + 3, block0, kBlock / 4, tr.rw_w1[axis]);
        // One flicker update every 4 samples: kBlock / 4 deviates a block.
        Fill(s + 4, block0 / 4, kBlock / 16, tr.flicker_w[axis][0]);
      }
    }
    const int64_t k_begin = int64_t{b} * kBlock + 1;
    driftlab::lockstep::Kernel<kW>::Advance(job, in, k_begin, k_begin + kBlock, true, group.get());
  }
  Digest state;
  for (int l = 0; l < kW; ++l) {
    state.Add(n.lat_rad[l]);
    state.Add(n.lon_rad[l]);
    state.Add(n.h_m[l]);
    for (int i = 0; i < 3; ++i) state.Add(n.v_eb_n[i][l]);
    for (int i = 0; i < 4; ++i) state.Add(n.q_b_n[i][l]);
    for (int t = 0; t < 2; ++t) {
      for (int i = 0; i < 3; ++i) {
        state.Add(group->triad[t].gm_state[i][l]);
        state.Add(group->triad[t].rw_state[i][l]);
        state.Add(group->triad[t].remainder[i][l]);
        state.Add(group->triad[t].flicker_state[i][0][l]);
      }
    }
  }
  Print("kernel_state", state);
  std::printf("lane_0_lat_lon_h %a %a %a\n", n.lat_rad[0], n.lon_rad[0], n.h_m[0]);

  driftlab::nav_error_lanes::TruthTerms truth{};
  truth.lat_rad = n.lat_rad[0] - 1e-6;
  truth.lon_rad = -3.1415;  // across the antimeridian from the estimates
  truth.h_m = n.h_m[0] + 3.0;
  truth.v_eb_n[0] = 9.0;
  truth.v_eb_n[1] = 24.0;
  truth.v_eb_n[2] = 0.0;
  truth.north_m = 6.36e6;
  truth.east_m = 6.39e6;
  truth.cos_L = 0.7071;
  truth.euler_rad[0] = 0.01;
  truth.euler_rad[1] = -0.02;
  truth.euler_rad[2] = -3.1;  // the yaw difference wraps
  double errors[driftlab::nav_error_lanes::kComponents][kMaxLanes];
  driftlab::lockstep::Kernel<kW>::Errors(truth, n, errors);
  Digest all;
  for (int l = 0; l < kW; ++l) {
    for (int c = 0; c < driftlab::nav_error_lanes::kComponents; ++c) all.Add(errors[c][l]);
  }
  Print("errors", all);
  std::printf("lane_0_errors_r %a %a %a\n", errors[0][0], errors[1][0], errors[2][0]);
}

}  // namespace

int main() {
  ElementaryFunctions();
  Deviates();
  KernelAndErrors();
  return 0;
}
