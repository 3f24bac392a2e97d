// The lane kernel of the lockstep NED runner (lockstep_ned.h), written once over the lane width
// W and compiled once per instruction set (lockstep_ned_{baseline,avx2,avx512}.cc include this
// file). Everything here has internal linkage and uses no Eigen or standard-library templates:
// each kernel file keeps its own copy, compiled for its instruction set only.
// At W = 1 (plain double) it is also the scalar code, so each step exists once:
// NedMechanization::Update (ins.cc) is NedStep at one lane, TriadErrorSimulator::ApplyIncrement
// (sensors.cc) is TriadStep at one lane; both files include this header (internal linkage, their
// own compile options).
//
// The arithmetic is lane-wise IEEE (GCC vector extensions: +, -, *, / and sqrt are correctly
// rounded per lane whatever the vector width) with -ffp-contract=off. The order of operations is
// that of NavEnvironment (earth.cc), RotationVectorToQuaternion (attitude.cc) and Eigen 3.4 for its
// small fixed-size expressions, so that the results equal the engine's Eigen code: Matrix3d *
// Vector3d as Dot3 below, squaredNorm of a 3-vector as x0 + (x1 + x2) (its unrolled reduction
// halves the range), the quaternion product as its SSE2/NEON kernel (Geometry_SIMD.h), q * v as
// _transformVector, normalized() as division by sqrt of (x^2 + z^2) + (y^2 + w^2) (two-lane
// packets).
// sin and cos are the engine's own (math/elementary_functions.h, also used by the scalar earth.cc
// and attitude.cc), computed for all W lanes at once; tan L is sin L / cos L in both.
#pragma once

#include <cstdint>

#include "lanes/lane.h"
#include "lockstep/lockstep_lanes.h"
#include "math/elementary_functions.h"
#include "random/random_kernels.h"
#include "stats/nav_error_lanes.h"

namespace driftlab::lockstep {
namespace {

template <int W>
struct Kernel {
  using P = lanes::D<W>;
  using U = lanes::U<W>;

  struct V3 {
    P x, y, z;
  };
  struct Q4 {
    P w, x, y, z;
  };

  static P Load(const double* p) {
    P v;
    __builtin_memcpy(&v, p, sizeof(v));
    return v;
  }
  static void Store(double* p, P v) { __builtin_memcpy(p, &v, sizeof(v)); }
  static P Splat(double x) {
    P v = {};
    return v + x;
  }
  static V3 Load3(const double (*a)[kMaxLanes]) { return {Load(a[0]), Load(a[1]), Load(a[2])}; }
  static void Store3(double (*a)[kMaxLanes], const V3& v) {
    Store(a[0], v.x);
    Store(a[1], v.y);
    Store(a[2], v.z);
  }
  static V3 Splat3(double x, double y, double z) { return {Splat(x), Splat(y), Splat(z)}; }

  static P Sqrt(P x) { return lanes::Sqrt<W>(x); }
  // All-ones lanes where the comparison holds.
  static U Mask(decltype(P{} < P{}) m) {
    if constexpr (W == 1) {
      return m ? ~uint64_t{0} : uint64_t{0};
    } else {
      return __builtin_bit_cast(U, m);
    }
  }

  // State fields of W lanes (x[lane] arrays of the lane structs, lockstep_lanes.h) or, for W = 1,
  // plain doubles (the scalar code's state): read and written alike.
  static P Get(const double (&a)[kMaxLanes]) { return Load(a); }
  static P Get(const double& x) requires(W == 1) { return x; }
  static void Put(double (&a)[kMaxLanes], P v) { Store(a, v); }
  static void Put(double& x, P v) requires(W == 1) { x = v; }
  template <typename A>
  static V3 Get3(const A& a) {
    return {Get(a[0]), Get(a[1]), Get(a[2])};
  }
  template <typename A>
  static void Put3(A& a, const V3& v) {
    Put(a[0], v.x);
    Put(a[1], v.y);
    Put(a[2], v.z);
  }

  static V3 Add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  static V3 Sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static V3 Scale(double s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
  static V3 Scale(const V3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
  static V3 ScaleP(const P& s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
  // The series' constant fractions as products with their rounded reciprocals: a division costs
  // several times a multiplication, and the rounding of 1/6 and 1/12 (<= 1.1e-16 relative) is far
  // below these second-order terms' own size.
  static constexpr double kOneSixth = 1.0 / 6.0;
  static constexpr double kOneTwelfth = 1.0 / 12.0;
  // Eigen's cross product of 3-vectors (OrthoMethods.h).
  static V3 Cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  // Eigen's q * v (_transformVector): uv = 2 (q.vec x v); v + w uv + q.vec x uv.
  static V3 Rotate(const Q4& q, const V3& v) {
    const V3 qv{q.x, q.y, q.z};
    V3 uv = Cross(qv, v);
    uv = Add(uv, uv);
    return Add(Add(v, ScaleP(q.w, uv)), Cross(qv, uv));
  }
  // Eigen's Quaternion<double> product, SSE2/NEON kernel (Geometry_SIMD.h), a * b.
  static Q4 Mul(const Q4& a, const Q4& b) {
    Q4 r;
    r.x = (a.w * b.x + a.y * b.z) - (a.z * b.y - a.x * b.w);
    r.y = (a.w * b.y + a.y * b.w) + (a.z * b.x - a.x * b.z);
    r.z = (a.w * b.z - a.y * b.x) + (a.z * b.w + a.x * b.y);
    r.w = (a.w * b.w - a.y * b.y) - (a.z * b.z + a.x * b.x);
    return r;
  }
  // Eigen's normalized() of a Quaternion<double> (coeffs x, y, z, w in two-lane packets); a zero
  // quaternion is returned as it is.
  static Q4 Normalized(const Q4& q) {
    const P n2 = (q.x * q.x + q.z * q.z) + (q.y * q.y + q.w * q.w);
    const P n = Sqrt(n2);
    const U positive = Mask(n2 > 0.0);
    return {lanes::Select<W>(positive, q.w / n, q.w), lanes::Select<W>(positive, q.x / n, q.x),
            lanes::Select<W>(positive, q.y / n, q.y), lanes::Select<W>(positive, q.z / n, q.z)};
  }
  // RotationVectorToQuaternion (attitude.cc): both of its branches for every lane, then the one
  // each lane's angle takes. Inlined, as Propagate: GCC otherwise calls them with their vector
  // arguments through memory, which is slower.
  __attribute__((always_inline)) static Q4 RotationVectorToQuaternion(const V3& rho) {
    const P a2 = rho.x * rho.x + (rho.y * rho.y + rho.z * rho.z);
    const P a = Sqrt(a2);
    const U small = Mask(a < 1e-4);
    // The Earth-rate rotation (~1e-6 rad a step) and a slowly turning body take the series in
    // every lane: sin and cos are then skipped (their lanes would not be selected).
    bool any_large = false;
    for (int i = 0; i < W; ++i) any_large = any_large || lanes::GetLane<W>(small, i) == 0;
    P sin_half = Splat(0.0), cos_half = Splat(1.0);
    if (any_large) elementary::SinCos<W>(0.5 * a, sin_half, cos_half);
    const P w = lanes::Select<W>(small, 1.0 - a2 * (1.0 / 8.0) + a2 * a2 * (1.0 / 384.0), cos_half);
    const P k =
        lanes::Select<W>(small, 0.5 - a2 * (1.0 / 48.0) + a2 * a2 * (1.0 / 3840.0), sin_half / a);
    return {w, k * rho.x, k * rho.y, k * rho.z};
  }

  // ---- Earth (earth.cc) ------------------------------------------------------------------------
  static constexpr double kA = 6378137.0;
  static constexpr double kF = 1.0 / 298.257223563;
  static constexpr double kE2 = kF * (2.0 - kF);
  static constexpr double kB = kA * (1.0 - kF);
  static constexpr double kOmega = 7.292115e-5;
  static constexpr double kGM = 3.986004418e14;
  static constexpr double kGammaE = 9.7803253359;
  static constexpr double kGammaP = 9.8321849378;

  // Per latitude, computed once and reused: sin L, cos L, and the two radii of curvature. The
  // scalar code (earth.cc) evaluates d = 1 - e^2 sin^2 L and sqrt(d) again in MeridianRadius and
  // TransverseRadius on every call, each time with the same operations on the same argument, so
  // the bits are the same.
  struct Lat {
    P L, s, c;
    P R_N0, R_E0;  // MeridianRadius(L), TransverseRadius(L)
  };
  static Lat LatOf(P L) {
    P s, c;
    elementary::SinCos<W>(L, s, c);
    return LatOfSinCos(L, s, c);
  }
  // The Lat of a latitude L near one already known (the step's midpoint and end from its start;
  // |L - base.L| ~ v dt / R, 5e-7 rad for 300 m/s at 100 Hz) by elementary::SinCosNear, so that
  // the step needs one full sin/cos of latitude instead of five.
  static Lat LatNear(const Lat& base, P L) {
    P s, c;
    elementary::SinCosNear<W>(L, base.L, base.s, base.c, s, c);
    return LatOfSinCos(L, s, c);
  }
  static Lat LatOfSinCos(P L, P s, P c) {
    Lat l{L, s, c, L, L};
    const P d = 1.0 - kE2 * l.s * l.s;
    const P sqrt_d = Sqrt(d);
    l.R_N0 = kA * (1.0 - kE2) / (d * sqrt_d);
    l.R_E0 = kA / sqrt_d;
    return l;
  }
  static P MeridianRadius(const Lat& l) { return l.R_N0; }
  static P TransverseRadius(const Lat& l) { return l.R_E0; }

  static V3 LlhRate(const EarthParams& e, const Lat& l, P h, const V3& v) {
    if (e.flat) return {v.x / e.flat_R_N_m, v.y / e.flat_R_E_m, -v.z};
    return {v.x / (MeridianRadius(l) + h), v.y / ((TransverseRadius(l) + h) * l.c), -v.z};
  }
  static V3 EarthRate(const EarthParams& e, const Lat& l) {
    if (e.flat) return Splat3(0.0, 0.0, 0.0);
    return {kOmega * l.c, Splat(0.0), -kOmega * l.s};
  }
  static V3 TransportRate(const EarthParams& e, const Lat& l, P h, const V3& v) {
    if (e.flat) return Splat3(0.0, 0.0, 0.0);
    const P R_E = TransverseRadius(l) + h;
    const P R_N = MeridianRadius(l) + h;
    return {v.y / R_E, -v.x / R_N, -v.y * (l.s / l.c) / R_E};
  }
  static V3 Gravity(const EarthParams& e, const Lat& l, P h) {
    if (e.flat) return Splat3(0.0, 0.0, e.flat_gravity_m_per_s2);
    // SomiglianaGravity and GravityNed, earth.cc.
    constexpr double k = kB * kGammaP / (kA * kGammaE) - 1.0;
    const P s2 = l.s * l.s;
    const P g0 = kGammaE * (1.0 + k * s2) / Sqrt(1.0 - kE2 * s2);
    constexpr double m = kOmega * kOmega * kA * kA * kB / kGM;
    const P g_D =
        g0 * (1.0 - 2.0 / kA * (1.0 + kF * (1.0 - 2.0 * s2) + m) * h + 3.0 * h * h / (kA * kA));
    const P g_N = -8.08e-9 * h * (2.0 * l.s * l.c);  // sin 2L = 2 sin L cos L (earth.cc)
    return {g_N, Splat(0.0), g_D};
  }

  // Row i of Eigen's Matrix3d * Vector3d from its three products: rows 0 and 1 are evaluated as
  // one two-lane packet accumulated column by column, (a0 + a1) + a2; row 2 as a scalar unrolled
  // reduction, a0 + (a1 + a2) (measured on Eigen 3.4 at -O2, SSE2).
  template <typename T>
  static T Dot3(int row, T a0, T a1, T a2) {
    return row < 2 ? (a0 + a1) + a2 : a0 + (a1 + a2);
  }

  // ---- Sensor error step (TriadErrorSimulator::ApplyIncrement runs it at W = 1) ---------------
  // `p` has TriadParams's fields, `t` TriadLanes's run-state fields (lane arrays, or plain doubles
  // for W = 1: sensors.cc), `dev` the step's deviates (Independent(i), GmW1(i), RwW1(i), and
  // Flicker(i, j, k, m) for component j of period 2^m at step k). `ideal` and `additive` are the
  // same for every lane (the shared truth); the result per lane.
  template <typename Params, typename State, typename Deviates>
  static V3 TriadStep(const Params& p, State& t, const Deviates& dev, const double ideal[3],
                      const double additive[3], uint64_t k, double dt) {
    double out[3][W];
    const double weight = dt;
    for (int i = 0; i < 3; ++i) {
      const P m0 = Get(t.scale_misalignment[i][0]);
      const P m1 = Get(t.scale_misalignment[i][1]);
      const P m2 = Get(t.scale_misalignment[i][2]);
      P y = Dot3(i, m0 * ideal[0], m1 * ideal[1], m2 * ideal[2]) + additive[i];
      if (p.asymmetry) y = y + p.half_asymmetry[i] * __builtin_fabs(ideal[i]);
      P e = Get(t.constant_bias[i]) * weight;
      // White noise, the GM integral's w2 part and the walk's bridge part: one deviate
      // (TriadJobConstants::independent_sigma, sensors.h).
      if (p.independent) e = e + p.independent_sigma * dev.Independent(i);
      if (p.gauss_markov) {
        const P w1 = dev.GmW1(i);
        const P b = Get(t.gm_state[i]);
        e = e + (p.gm_mean_gain * b + p.gm_integral_w1_gain * w1);
        Put(t.gm_state[i], p.gm_decay * b + p.gm_drive_sigma * w1);
      }
      if (p.random_walk) {
        const P step = p.rw_step_sigma * dev.RwW1(i);
        const P b = Get(t.rw_state[i]);
        e = e + (b * dt + 0.5 * dt * step);
        Put(t.rw_state[i], b + step);
      }
      if (p.n_flicker > 0) {
        P sum = Splat(0.0);
        for (int j = 0; j < p.n_flicker; ++j) {
          const int m = p.flicker_period_log2[j];
          const uint64_t mask = (uint64_t{1} << m) - 1;
          P x = Get(t.flicker_state[i][j]);
          if (k != 0 && (k & mask) == 0) {
            x = p.flicker_decay[j] * x + p.flicker_drive_sigma[j] * dev.Flicker(i, j, k, m);
            Put(t.flicker_state[i][j], x);
          }
          sum = sum + x;
        }
        e = e + sum * weight;
      }
      P v = y + e;
      if (p.range > 0.0) {
        const double lo = -p.range * weight, hi = p.range * weight;
        v = lanes::Clamp<W>(v, lo, hi);
      }
      if (p.quantization > 0.0) {
        const double lsb = p.quantization;
        const P carried = v + Get(t.remainder[i]);
        const P q = lanes::Floor<W>(carried / lsb + 0.5);
        const P o = lsb * q;
        Put(t.remainder[i], carried - o);
        v = o;
      }
      Store(out[i], v);
    }
    return {Load(out[0]), Load(out[1]), Load(out[2])};
  }

  // ---- Mechanization (NedMechanization::Update runs it at W = 1)
  // ---------------------------------------
  struct Step {
    P L, lon, h;
    V3 v, zeta;
  };

  // kPredictor: the predictor's pass, whose result only places the corrector's midpoint (L, h, v
  // averaged with the start). It leaves out what moves that midpoint by less than rounding: the
  // two terms of second order in zeta (1/12 zeta x w ~ 3e-12 m/s, 1/6 zeta x (zeta x u) ~ 1e-14
  // m/s in a 3 deg/s turn at 100 Hz; through the corrector's Coriolis term they change the step by
  // ~1e-18 m/s), and it takes the end point's radii of curvature at the midpoint (predicted L off
  // by ~(dL/2)^2 e^2 ~ 6e-16 rad, two ulp of L, at 300 m/s). The corrector evaluates all of them.
  template <bool kPredictor, typename Job>
  __attribute__((always_inline)) static Step Propagate(
      const Job& job, const Q4& q, const Lat& lat, const P& lon, const P& h, const V3& v_old,
      const V3& delta_v_b, const V3& alpha_cross_dv, const V3& second_order_b,
      const V3& llh_rate_old, const P& L_mid, const P& h_mid, const V3& v_mid) {
    const double dt = job.dt_s;
    const EarthParams& e = job.earth;
    const P& L = lat.L;  // the step's start
    const Lat lat_mid = LatNear(lat, L_mid);
    Step s;
    // Navigation-frame rotation over the interval, rotation rate taken at the midpoint:
    //   zeta = (omega_ie_n + omega_en_n)(mid) dt                               Groves (5.73)-(5.76)
    const V3 omega_ie_n = EarthRate(e, lat_mid);
    const V3 omega_en_n = TransportRate(e, lat_mid, h_mid, v_mid);
    s.zeta = Scale(Add(omega_ie_n, omega_en_n), dt);
    const V3& zeta = s.zeta;
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
    const V3 u = Rotate(q, delta_v_b);
    const V3 first_order = Sub(Add(u, Rotate(q, second_order_b)), Scale(0.5, Cross(zeta, u)));
    const V3 delta_v_sf_n =
        kPredictor
            ? first_order
            : Add(Sub(first_order, Scale(Cross(zeta, Rotate(q, alpha_cross_dv)), kOneTwelfth)),
                  Scale(Cross(zeta, Cross(zeta, u)), kOneSixth));
    // Gravity and Coriolis at the midpoint:
    //   v(k+1) = v(k) + delta_v_sf_n + (g_b_n - (omega_en_n + 2 omega_ie_n) x v_eb_n)(mid) dt
    //                                                                                 Groves (5.54)
    const V3 g_b_n = Gravity(e, lat_mid, h_mid);
    s.v = Add(Add(v_old, delta_v_sf_n),
              Scale(Sub(g_b_n, Cross(Add(omega_en_n, Scale(2.0, omega_ie_n)), v_mid)), dt));
    // Position by the trapezoidal rule on (L, lambda, h), Groves (5.56)-style: the rate of
    // (L, lambda, h) with the old velocity at the old position (llh_rate_old) and with the new
    // velocity at the new position. The new latitude inside the second evaluation only scales
    // R_N, R_E and cos L, so a predicted value (error O(dt^2)) is enough: it enters the step at
    // O(dt^3 v / R^2).
    // 2 L_mid - L_k is the midpoint-rule prediction of L_k+1 (exactly the predicted L_k+1 in the
    // corrector, whose L_mid is the average of the two).
    const P L_new_predicted = 2.0 * L_mid - L;
    const P h_new = h - 0.5 * dt * (v_old.z + s.v.z);
    const V3 rate_new =
        LlhRate(e, kPredictor ? lat_mid : LatNear(lat, L_new_predicted), h_new, s.v);
    s.L = L + 0.5 * dt * (llh_rate_old.x + rate_new.x);
    s.lon = lon + 0.5 * dt * (llh_rate_old.y + rate_new.y);
    s.h = h_new;
    return s;
  }

  // `job` has dt_s, earth and coning_sculling (KernelJob, or NedStepJob in ins.cc); `n` the fields
  // of NavLanes (lane arrays, or plain doubles for W = 1: NedMechanization's state, ins.cc).
  template <typename Job, typename Nav>
  static void NedStep(const Job& job, Nav& n, const V3& dtheta, const V3& dv) {
    const double dt = job.dt_s;
    // Body attitude increment and specific-force increment in the body frame at t_k.
    //   alpha = dtheta_k + 1/12 dtheta_{k-1} x dtheta_k                     (two-sample coning)
    //   dv_b = dv_k + 1/2 dtheta_k x dv_k + 1/12 (dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k)
    //                                      (rotation compensation + two-sample sculling)
    // Savage (1998) part 1 (eqs. 15, 28), part 2 (eqs. 19, 20); Groves (5.97)-(5.98). Both are
    // exact for angular rate and specific force linear in time (to first order in the rotation; the
    // second-order term follows in Propagate). On the first step no previous increment
    // exists; the constant-rate assumption (previous = current) makes the 1/12 terms vanish.
    V3 alpha = dtheta;
    V3 delta_v_b = dv;
    V3 alpha_cross_dv = Splat3(0.0, 0.0, 0.0);
    V3 second_order_b = Splat3(0.0, 0.0, 0.0);
    const V3 previous_dtheta = Get3(n.previous_dtheta);
    const V3 previous_dv = Get3(n.previous_dv);
    if (job.coning_sculling) {
      alpha_cross_dv = Cross(dtheta, dv);
      // Second-order rotation compensation 1/6 alpha x (alpha x dv) (exact integral of
      // exp([omega t x]) f for constant omega and f, Savage (1998) part 2).
      second_order_b = Scale(Cross(dtheta, alpha_cross_dv), kOneSixth);
      delta_v_b = Add(delta_v_b, Scale(0.5, alpha_cross_dv));
      if (n.have_previous) {
        alpha = Add(alpha, Scale(Cross(previous_dtheta, dtheta), kOneTwelfth));
        delta_v_b =
            Add(delta_v_b,
                Scale(Add(Cross(previous_dtheta, dv), Cross(previous_dv, dtheta)), kOneTwelfth));
      }
    }
    const P L = Get(n.lat_rad), lon = Get(n.lon_rad), h = Get(n.h_m);
    const V3 v = Get3(n.v_eb_n);
    const V3 previous_v = Get3(n.previous_v_eb_n);
    const Q4 q{Get(n.q_b_n[0]), Get(n.q_b_n[1]), Get(n.q_b_n[2]), Get(n.q_b_n[3])};
    // Predictor: midpoint velocity extrapolated from the last two epochs, midpoint position by half
    // an Euler step with it.
    const V3 v_mid_predicted = n.have_previous ? Sub(Scale(1.5, v), Scale(0.5, previous_v)) : v;
    const Lat lat = LatOf(L);
    const V3 llh_rate_old = LlhRate(job.earth, lat, h, v);
    const V3 llh_rate_mid = LlhRate(job.earth, lat, h, v_mid_predicted);
    const Step predicted = Propagate<true>(
        job, q, lat, lon, h, v, delta_v_b, alpha_cross_dv, second_order_b, llh_rate_old,
        L + 0.5 * dt * llh_rate_mid.x, h + 0.5 * dt * llh_rate_mid.z, v_mid_predicted);
    // Corrector: midpoint quantities as averages of the old and the predicted new state.
    const Step corrected = Propagate<false>(
        job, q, lat, lon, h, v, delta_v_b, alpha_cross_dv, second_order_b, llh_rate_old,
        0.5 * (L + predicted.L), 0.5 * (h + predicted.h), Scale(0.5, Add(v, predicted.v)));
    // Attitude: C_b_n(k+1) = C_n(k)_n(k+1) C_b_n(k) C_b(k+1)_b(k), each factor the exact rotation
    // of its rotation vector:  q_b_n(k+1) = q(-zeta) q_b_n(k) q(alpha).                Groves
    // (5.75)
    const V3 minus_zeta{-corrected.zeta.x, -corrected.zeta.y, -corrected.zeta.z};
    const Q4 q_new = Normalized(
        Mul(Mul(RotationVectorToQuaternion(minus_zeta), q), RotationVectorToQuaternion(alpha)));
    Put(n.q_b_n[0], q_new.w);
    Put(n.q_b_n[1], q_new.x);
    Put(n.q_b_n[2], q_new.y);
    Put(n.q_b_n[3], q_new.z);
    Put3(n.previous_v_eb_n, v);
    Put3(n.previous_dtheta, dtheta);
    Put3(n.previous_dv, dv);
    Put(n.lat_rad, corrected.L);
    Put(n.lon_rad, corrected.lon);
    Put(n.h_m, corrected.h);
    Put3(n.v_eb_n, corrected.v);
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
            g_term[i] = Dot3(i, G[0] * ideal[3], G[1] * ideal[4], G[2] * ideal[5]);
          }
        }
        const double zero[3] = {0.0, 0.0, 0.0};
        const LaneDeviates gyro{group->triad[0], j, block_begin};
        const LaneDeviates accel{group->triad[1], j, block_begin};
        dtheta = TriadStep(job.triad[0], group->triad[0], gyro, ideal, g_term, d, job.dt_s);
        dv = TriadStep(job.triad[1], group->triad[1], accel, ideal + 3, zero, d, job.dt_s);
      } else {
        dtheta = Splat3(ideal[0], ideal[1], ideal[2]);
        dv = Splat3(ideal[3], ideal[4], ideal[5]);
      }
      if (!navigate) {
        Store3(n.sum_dtheta, Add(Load3(n.sum_dtheta), dtheta));
        Store3(n.sum_dv, Add(Load3(n.sum_dv), dv));
        continue;
      }
      NedStep(job, n, dtheta, dv);
      n.have_previous = 1;
      ++n.steps;
      if (job.truth_height) {
        Store(n.h_m, Splat(in.h_m[k]));
        Store(n.v_eb_n[2], Splat(in.v_D_m_per_s[k]));
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
