// The lane kernel of the lockstep NED runner (lockstep_ned.h): the per-sample loop that advances a
// group of W runs (the sensor-error step, sensors/triad_step.h, then the mechanization step,
// ins/ned_step.h, both written over the lane width), and the statistics' error components of the W
// runs (stats/nav_error_lanes.h). Compiled once per instruction set:
// lockstep_ned_{baseline,avx2,avx512}.cc include this file, each with its own options. Everything
// here and in the headers it includes has internal linkage and uses no Eigen or standard-library
// templates (lanes/lane.h): each kernel file keeps its own copy, compiled for its instruction set
// only. The arithmetic is lane-wise IEEE (GCC vector extensions: +, -, *, / and sqrt are correctly
// rounded per lane whatever the vector width) with -ffp-contract=off, so a lane's result equals
// the scalar code's (the same steps at W = 1, in ins.cc and sensors.cc).
#pragma once

#include <cstdint>

#include "ins/ned_step.h"
#include "lanes/lane.h"
#include "lockstep/lockstep_lanes.h"
#include "math/vector_lanes.h"
#include "random/random_kernels.h"
#include "sensors/triad_step.h"
#include "stats/nav_error_lanes.h"

namespace driftlab::lockstep {
namespace {

template <int W>
struct Kernel {
  using P = lanes::D<W>;
  using V3 = vector_lanes::V3<W>;

  static P Load(const double* p) { return lanes::Load<W>(p); }
  static void Store(double* p, P v) { lanes::Store<W>(p, v); }
  static V3 Load3(const double (*a)[kMaxLanes]) { return {Load(a[0]), Load(a[1]), Load(a[2])}; }
  static void Store3(double (*a)[kMaxLanes], const V3& v) {
    Store(a[0], v.x);
    Store(a[1], v.y);
    Store(a[2], v.z);
  }

  // The deviates of one step of a lane group: [axis][j][lane] of the block's buffers (TriadLanes).
  struct LaneDeviates {
    const TriadLanes& t;
    int j;                 // step - block_begin
    uint64_t block_begin;  // first step of the block
    P Independent(int i) const { return Load(t.independent[i][j]); }
    P GmW1(int i) const { return Load(t.gm_w1[i][j]); }
    P RwW1(int i) const { return Load(t.rw_w1[i][j]); }
    P Flicker(int i, int c, uint64_t k, int m) const {
      return Load(t.flicker_w[i][c][(k - block_begin) >> m]);
    }
  };

  // Sample k (increment over (t_{k-1}, t_k]) is the sensor's step d = k - 1 (its deviate index,
  // TriadErrorSimulator::step()); the block holds the deviates of steps [block_begin, +kBlock).
  static void Advance(const KernelJob& job, const KernelInputs& in, int64_t k_begin, int64_t k_end,
                      bool navigate, LockstepGroup* group) {
    const uint64_t block_begin = static_cast<uint64_t>(k_begin - 1) & ~uint64_t{kBlock - 1};
    NavLanes& n = group->nav;
    for (int64_t k = k_begin; k < k_end; ++k) {
      const double* ideal = in.increments + 6 * k;
      V3 dtheta, dv;
      if (job.has_sensor) {
        const uint64_t d = static_cast<uint64_t>(k - 1);
        const int j = static_cast<int>(d - block_begin);
        double g_term[3] = {0.0, 0.0, 0.0};
        if (job.g_sensitivity) {
          for (int i = 0; i < 3; ++i) {
            const double* G = job.gyro_g_sensitivity[i];
            g_term[i] = vector_lanes::Dot3(i, G[0] * ideal[3], G[1] * ideal[4], G[2] * ideal[5]);
          }
        }
        const double zero[3] = {0.0, 0.0, 0.0};
        const LaneDeviates gyro{group->triad[0], j, block_begin};
        const LaneDeviates accel{group->triad[1], j, block_begin};
        dtheta = triad_step::TriadStep<W>(job.triad[0], group->triad[0], gyro, ideal, g_term, d,
                                          job.dt_s);
        dv = triad_step::TriadStep<W>(job.triad[1], group->triad[1], accel, ideal + 3, zero, d,
                                      job.dt_s);
      } else {
        dtheta = vector_lanes::Splat3<W>(ideal[0], ideal[1], ideal[2]);
        dv = vector_lanes::Splat3<W>(ideal[3], ideal[4], ideal[5]);
      }
      if (!navigate) {
        Store3(n.sum_dtheta, vector_lanes::Add(Load3(n.sum_dtheta), dtheta));
        Store3(n.sum_dv, vector_lanes::Add(Load3(n.sum_dv), dv));
        continue;
      }
      ned_step::NedStep<W>(job, n, dtheta, dv);
      n.have_previous = 1;
      ++n.steps;
      if (job.truth_height) {
        Store(n.h_m, lanes::Splat<W>(in.h_m[k]));
        Store(n.v_eb_n[2], lanes::Splat<W>(in.v_D_m_per_s[k]));
      }
    }
  }

  // The statistics' error components of the W lanes of `n` against one truth (KernelEntry::errors).
  static void Errors(const nav_error_lanes::TruthTerms& truth, const NavLanes& n,
                     double (*out)[kMaxLanes]) {
    const P v[3] = {Load(n.v_eb_n[0]), Load(n.v_eb_n[1]), Load(n.v_eb_n[2])};
    const P q[4] = {Load(n.q_b_n[0]), Load(n.q_b_n[1]), Load(n.q_b_n[2]), Load(n.q_b_n[3])};
    P e[nav_error_lanes::kComponents];
    nav_error_lanes::ErrorComponents<W>(truth, Load(n.lat_rad), Load(n.lon_rad), Load(n.h_m), v, q,
                                        e);
    for (int c = 0; c < nav_error_lanes::kComponents; ++c) Store(out[c], e[c]);
  }
};

}  // namespace
}  // namespace driftlab::lockstep
