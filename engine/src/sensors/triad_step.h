// The sensor-error step of one triad (gyro or accelerometer) over one sample interval, written once
// over the lane width W (lanes/lane.h): at W = 1 it is TriadErrorSimulator::ApplyIncrement
// (sensors.cc), at W > 1 the step of W lockstep runs at once (lockstep/lockstep_ned_kernel.h, one
// copy per instruction set). The error model and its discretisation are sensors.h's
// (TriadJobConstants: scale factor and misalignment, asymmetry, constant bias, white noise,
// first-order Gauss-Markov, random walk, flicker as a sum of Gauss-Markov components, range and
// quantization with carried remainder).
// A lane header (lanes/lane.h): internal linkage, no Eigen or standard-library templates.
#pragma once

#include <cstdint>

#include "lanes/lane.h"
#include "math/vector_lanes.h"

namespace driftlab::triad_step {
namespace {

using lanes::D;
using vector_lanes::V3;

// The measured increment of one triad over sample interval k: the ideal increment through the
// scale-factor and misalignment matrix, plus `additive` (the gyro's g-sensitivity term), plus the
// integrated errors over dt. `p` has TriadStepParams's fields (driftlab/triad_step_params.h), `t`
// the run state (scale_misalignment[3][3], constant_bias[3], gm_state[3], rw_state[3],
// remainder[3], flicker_state[3][j]: lane arrays, or plain doubles for W = 1), `dev` the step's
// deviates (Independent(i), GmW1(i), RwW1(i), and Flicker(i, j, k, m) for component j of period
// 2^m at step k). `ideal` and `additive` are the same for every lane (the shared truth); the
// result per lane.
template <int W, typename Params, typename State, typename Deviates>
inline V3<W> TriadStep(const Params& p, State& t, const Deviates& dev, const double ideal[3],
                       const double additive[3], uint64_t k, double dt) {
  using lanes::Get;
  using lanes::Put;
  double out[3][W];
  const double weight = dt;
  for (int i = 0; i < 3; ++i) {
    const D<W> m0 = Get<W>(t.scale_misalignment[i][0]);
    const D<W> m1 = Get<W>(t.scale_misalignment[i][1]);
    const D<W> m2 = Get<W>(t.scale_misalignment[i][2]);
    D<W> y = vector_lanes::Dot3(i, m0 * ideal[0], m1 * ideal[1], m2 * ideal[2]) + additive[i];
    if (p.asymmetry) y = y + p.half_asymmetry[i] * __builtin_fabs(ideal[i]);
    D<W> e = Get<W>(t.constant_bias[i]) * weight;
    // White noise, the GM integral's w2 part and the walk's bridge part: one deviate
    // (TriadJobConstants::independent_sigma, sensors.h).
    if (p.independent) e = e + p.independent_sigma * dev.Independent(i);
    if (p.gauss_markov) {
      const D<W> w1 = dev.GmW1(i);
      const D<W> b = Get<W>(t.gm_state[i]);
      e = e + (p.gm_mean_gain * b + p.gm_integral_w1_gain * w1);
      Put<W>(t.gm_state[i], p.gm_decay * b + p.gm_drive_sigma * w1);
    }
    if (p.random_walk) {
      const D<W> step = p.rw_step_sigma * dev.RwW1(i);
      const D<W> b = Get<W>(t.rw_state[i]);
      e = e + (b * dt + 0.5 * dt * step);
      Put<W>(t.rw_state[i], b + step);
    }
    if (p.n_flicker > 0) {
      D<W> sum = lanes::Splat<W>(0.0);
      for (int j = 0; j < p.n_flicker; ++j) {
        const int m = p.flicker_period_log2[j];
        const uint64_t mask = (uint64_t{1} << m) - 1;
        D<W> x = Get<W>(t.flicker_state[i][j]);
        if (k != 0 && (k & mask) == 0) {
          x = p.flicker_decay[j] * x + p.flicker_drive_sigma[j] * dev.Flicker(i, j, k, m);
          Put<W>(t.flicker_state[i][j], x);
        }
        sum = sum + x;
      }
      e = e + sum * weight;
    }
    D<W> v = y + e;
    if (p.range > 0.0) {
      const double lo = -p.range * weight, hi = p.range * weight;
      v = lanes::Clamp<W>(v, lo, hi);
    }
    if (p.quantization > 0.0) {
      const double lsb = p.quantization;
      const D<W> carried = v + Get<W>(t.remainder[i]);
      const D<W> q = lanes::Floor<W>(carried / lsb + 0.5);
      const D<W> o = lsb * q;
      Put<W>(t.remainder[i], carried - o);
      v = o;
    }
    lanes::Store<W>(out[i], v);
  }
  return {lanes::Load<W>(out[0]), lanes::Load<W>(out[1]), lanes::Load<W>(out[2])};
}

}  // namespace
}  // namespace driftlab::triad_step
