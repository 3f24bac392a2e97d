// The NED mechanization step (mechanization A, ins.h), written once over the lane width W
// (lanes/lane.h): at W = 1 it is NedMechanization::Update (ins.cc), at W > 1 the step of W
// lockstep runs at once (lockstep/lockstep_ned_kernel.h, one copy per instruction set).
// Two-sample coning and sculling, the specific-force transformation to second order in the body and
// navigation-frame rotations, gravity, Coriolis and the frame rotation at the interval midpoint
// (one predictor-corrector pass), position by the trapezoidal rule; the Earth model is
// earth/earth_lanes.h. Savage, "Strapdown Inertial Navigation Integration Algorithm Design", JGCD
// 21(1) and 21(2), 1998; Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
// Navigation Systems", 2nd ed. (2013), section 5.5.
//
// The arithmetic is lane-wise IEEE with -ffp-contract=off, in the order of the engine's Eigen code
// for its small fixed-size expressions (math/vector_lanes.h), so every W gives the same bits.
// A lane header (lanes/lane.h): internal linkage, no Eigen or standard-library templates.
#pragma once

#include "driftlab/earth_constants.h"
#include "earth/earth_lanes.h"
#include "lanes/lane.h"
#include "math/vector_lanes.h"

namespace driftlab::ned_step {
namespace {

using earth_lanes::Lat;
using lanes::D;
using vector_lanes::Q4;
using vector_lanes::V3;

// The series' constant fractions as products with their rounded reciprocals: a division costs
// several times a multiplication, and the rounding of 1/6 and 1/12 (<= 1.1e-16 relative) is far
// below these second-order terms' own size.
constexpr double kOneSixth = 1.0 / 6.0;
constexpr double kOneTwelfth = 1.0 / 12.0;

// One pass of the step: the new position, velocity and the navigation-frame rotation zeta.
template <int W>
struct Pass {
  D<W> L, lon, h;
  V3<W> v, zeta;
};

// kPredictor: the predictor's pass, whose result only places the corrector's midpoint (L, h, v
// averaged with the start). It leaves out what moves that midpoint by less than rounding: the
// two terms of second order in zeta (1/12 zeta x w ~ 3e-12 m/s, 1/6 zeta x (zeta x u) ~ 1e-14
// m/s in a 3 deg/s turn at 100 Hz; through the corrector's Coriolis term they change the step by
// ~1e-18 m/s), and it takes the end point's radii of curvature at the midpoint (predicted L off
// by ~(dL/2)^2 e^2 ~ 6e-16 rad, two ulp of L, at 300 m/s). The corrector evaluates all of them.
// Inlined: GCC otherwise calls it with its vector arguments through memory, which is slower.
template <int W, bool kPredictor>
__attribute__((always_inline)) inline Pass<W> Propagate(
    const EarthParams& e, double dt, const Q4<W>& q, const Lat<W>& lat, const D<W>& lon,
    const D<W>& h, const V3<W>& v_old, const V3<W>& delta_v_b, const V3<W>& alpha_cross_dv,
    const V3<W>& second_order_b, const V3<W>& llh_rate_old, const D<W>& L_mid, const D<W>& h_mid,
    const V3<W>& v_mid) {
  using vector_lanes::Add;
  using vector_lanes::Cross;
  using vector_lanes::Rotate;
  using vector_lanes::Scale;
  using vector_lanes::Sub;
  const D<W>& L = lat.L;  // the step's start
  const Lat<W> lat_mid = earth_lanes::LatNear<W>(lat, L_mid);
  Pass<W> s;
  // Navigation-frame rotation over the interval, rotation rate taken at the midpoint:
  //   zeta = (omega_ie_n + omega_en_n)(mid) dt                               Groves (5.73)-(5.76)
  const V3<W> omega_ie_n = earth_lanes::EarthRate<W>(e, lat_mid.s, lat_mid.c);
  const V3<W> omega_en_n = earth_lanes::TransportRate<W>(e, lat_mid, h_mid, v_mid);
  s.zeta = Scale(Add(omega_ie_n, omega_en_n), dt);
  const V3<W>& zeta = s.zeta;
  // Specific-force velocity increment resolved in n, delta_v_sf_n = integral of
  // C_n(k)^n(t) C_b_n(k) C_b(t)^b(k) f_ib_b dt, expanded to second order in the body rotation
  // alpha and the n-frame rotation zeta (rates constant over the interval; the linear variation
  // is the sculling term already in delta_v_b):
  //   integral = x + 1/2 w + 1/6 C alpha x (alpha x dv) - 1/2 zeta x x - 1/3 zeta x w
  //              + 1/6 zeta x (zeta x x),        x = C_b_n(k) dv, w = C_b_n(k) (alpha x dv)
  // (the -1/3 from integrating s^2 over the cross term of the two rotations). With
  // u = x + 1/2 w = C_b_n(k) delta_v_b (delta_v_b holding dv + 1/2 alpha x dv + sculling):
  //   delta_v_sf_n = u + 1/6 C alpha x (alpha x dv) - 1/2 zeta x u - 1/12 zeta x w
  //                  + 1/6 zeta x (zeta x u)               + O(3rd order)
  // Savage (1998) part 2 section 3 (the first-order form is his eq. 24).
  // The second-order terms matter: at 10 Hz a stationary body otherwise drifts by
  // 1/4 zeta x (zeta x g dt) ~ 1e-11 m/s per step, and in a 0.5 rad/s turn 1/6 alpha^2 dv reaches
  // 2e-7 m/s per step at 100 Hz.
  const V3<W> u = Rotate(q, delta_v_b);
  const V3<W> first_order = Sub(Add(u, Rotate(q, second_order_b)), Scale(0.5, Cross(zeta, u)));
  const V3<W> delta_v_sf_n =
      kPredictor ? first_order
                 : Add(Sub(first_order, Scale(Cross(zeta, Rotate(q, alpha_cross_dv)), kOneTwelfth)),
                       Scale(Cross(zeta, Cross(zeta, u)), kOneSixth));
  // Gravity and Coriolis at the midpoint:
  //   v(k+1) = v(k) + delta_v_sf_n + (g_b_n - (omega_en_n + 2 omega_ie_n) x v_eb_n)(mid) dt
  //                                                                                 Groves (5.54)
  const V3<W> g_b_n = earth_lanes::Gravity<W>(e, lat_mid.s, lat_mid.c, h_mid);
  s.v = Add(Add(v_old, delta_v_sf_n),
            Scale(Sub(g_b_n, Cross(Add(omega_en_n, Scale(2.0, omega_ie_n)), v_mid)), dt));
  // Position by the trapezoidal rule on (L, lambda, h), Groves (5.56)-style: the rate of
  // (L, lambda, h) with the old velocity at the old position (llh_rate_old) and with the new
  // velocity at the new position. The new latitude inside the second evaluation only scales
  // R_N, R_E and cos L, so a predicted value (error O(dt^2)) is enough: it enters the step at
  // O(dt^3 v / R^2).
  // 2 L_mid - L_k is the midpoint-rule prediction of L_k+1 (exactly the predicted L_k+1 in the
  // corrector, whose L_mid is the average of the two).
  const D<W> L_new_predicted = 2.0 * L_mid - L;
  const D<W> h_new = h - 0.5 * dt * (v_old.z + s.v.z);
  const V3<W> rate_new = earth_lanes::LlhRate<W>(
      e, kPredictor ? lat_mid : earth_lanes::LatNear<W>(lat, L_new_predicted), h_new, s.v);
  s.L = L + 0.5 * dt * (llh_rate_old.x + rate_new.x);
  s.lon = lon + 0.5 * dt * (llh_rate_old.y + rate_new.y);
  s.h = h_new;
  return s;
}

// Advances the navigation state `n` by one interval with the increments dtheta, dv.
// `job` has dt_s, earth (EarthParams) and coning_sculling (lockstep::KernelJob, or NedStepJob in
// ins.cc); `n` the fields of lockstep::NavLanes (lane arrays, or plain doubles for W = 1:
// NedMechanization's state, ins.cc): lat_rad, lon_rad, h_m, v_eb_n[3], q_b_n[4] (w, x, y, z),
// previous_dtheta[3], previous_dv[3], previous_v_eb_n[3] and have_previous (the same for every
// lane).
template <int W, typename Job, typename Nav>
inline void NedStep(const Job& job, Nav& n, const V3<W>& dtheta, const V3<W>& dv) {
  using lanes::Get;
  using lanes::Put;
  using vector_lanes::Add;
  using vector_lanes::Cross;
  using vector_lanes::Scale;
  using vector_lanes::Sub;
  const double dt = job.dt_s;
  // Body attitude increment and specific-force increment in the body frame at t_k.
  //   alpha = dtheta_k + 1/12 dtheta_{k-1} x dtheta_k                     (two-sample coning)
  //   dv_b = dv_k + 1/2 dtheta_k x dv_k + 1/12 (dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k)
  //                                      (rotation compensation + two-sample sculling)
  // Savage (1998) part 1 (eqs. 15, 28), part 2 (eqs. 19, 20); Groves (5.97)-(5.98). Both are
  // exact for angular rate and specific force linear in time (to first order in the rotation; the
  // second-order term follows in Propagate). On the first step no previous increment
  // exists; the constant-rate assumption (previous = current) makes the 1/12 terms vanish.
  V3<W> alpha = dtheta;
  V3<W> delta_v_b = dv;
  V3<W> alpha_cross_dv = vector_lanes::Splat3<W>(0.0, 0.0, 0.0);
  V3<W> second_order_b = vector_lanes::Splat3<W>(0.0, 0.0, 0.0);
  const V3<W> previous_dtheta = vector_lanes::Get3<W>(n.previous_dtheta);
  const V3<W> previous_dv = vector_lanes::Get3<W>(n.previous_dv);
  if (job.coning_sculling) {
    alpha_cross_dv = Cross(dtheta, dv);
    // Second-order rotation compensation 1/6 alpha x (alpha x dv) (exact integral of
    // exp([omega t x]) f for constant omega and f, Savage (1998) part 2).
    second_order_b = Scale(Cross(dtheta, alpha_cross_dv), kOneSixth);
    delta_v_b = Add(delta_v_b, Scale(0.5, alpha_cross_dv));
    if (n.have_previous) {
      alpha = Add(alpha, Scale(Cross(previous_dtheta, dtheta), kOneTwelfth));
      delta_v_b = Add(delta_v_b, Scale(Add(Cross(previous_dtheta, dv), Cross(previous_dv, dtheta)),
                                       kOneTwelfth));
    }
  }
  const D<W> L = Get<W>(n.lat_rad), lon = Get<W>(n.lon_rad), h = Get<W>(n.h_m);
  const V3<W> v = vector_lanes::Get3<W>(n.v_eb_n);
  const V3<W> previous_v = vector_lanes::Get3<W>(n.previous_v_eb_n);
  const Q4<W> q{Get<W>(n.q_b_n[0]), Get<W>(n.q_b_n[1]), Get<W>(n.q_b_n[2]), Get<W>(n.q_b_n[3])};
  // Predictor: midpoint velocity extrapolated from the last two epochs, midpoint position by half
  // an Euler step with it.
  const V3<W> v_mid_predicted = n.have_previous ? Sub(Scale(1.5, v), Scale(0.5, previous_v)) : v;
  const Lat<W> lat = earth_lanes::LatOf<W>(L);
  const EarthParams& e = job.earth;
  const V3<W> llh_rate_old = earth_lanes::LlhRate<W>(e, lat, h, v);
  const V3<W> llh_rate_mid = earth_lanes::LlhRate<W>(e, lat, h, v_mid_predicted);
  const Pass<W> predicted = Propagate<W, true>(
      e, dt, q, lat, lon, h, v, delta_v_b, alpha_cross_dv, second_order_b, llh_rate_old,
      L + 0.5 * dt * llh_rate_mid.x, h + 0.5 * dt * llh_rate_mid.z, v_mid_predicted);
  // Corrector: midpoint quantities as averages of the old and the predicted new state.
  const Pass<W> corrected = Propagate<W, false>(
      e, dt, q, lat, lon, h, v, delta_v_b, alpha_cross_dv, second_order_b, llh_rate_old,
      0.5 * (L + predicted.L), 0.5 * (h + predicted.h), Scale(0.5, Add(v, predicted.v)));
  // Attitude: C_b_n(k+1) = C_n(k)_n(k+1) C_b_n(k) C_b(k+1)_b(k), each factor the exact rotation
  // of its rotation vector:  q_b_n(k+1) = q(-zeta) q_b_n(k) q(alpha).             Groves (5.75)
  const V3<W> minus_zeta{-corrected.zeta.x, -corrected.zeta.y, -corrected.zeta.z};
  const Q4<W> q_new = vector_lanes::Normalized(
      vector_lanes::Mul(vector_lanes::Mul(vector_lanes::RotationVectorToQuaternion(minus_zeta), q),
                        vector_lanes::RotationVectorToQuaternion(alpha)));
  Put<W>(n.q_b_n[0], q_new.w);
  Put<W>(n.q_b_n[1], q_new.x);
  Put<W>(n.q_b_n[2], q_new.y);
  Put<W>(n.q_b_n[3], q_new.z);
  vector_lanes::Put3<W>(n.previous_v_eb_n, v);
  vector_lanes::Put3<W>(n.previous_dtheta, dtheta);
  vector_lanes::Put3<W>(n.previous_dv, dv);
  Put<W>(n.lat_rad, corrected.L);
  Put<W>(n.lon_rad, corrected.lon);
  Put<W>(n.h_m, corrected.h);
  vector_lanes::Put3<W>(n.v_eb_n, corrected.v);
}

}  // namespace
}  // namespace driftlab::ned_step
