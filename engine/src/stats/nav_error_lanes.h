// The navigation errors that go into the Monte-Carlo statistics (ErrorComponentsOf,
// mc_statistics.h: position, velocity and Euler-angle errors, horizontal and 3-D position error),
// written once over a lane type (lanes/lane.h): W = 1 is the scalar code (earth.cc's
// PositionErrorNed, attitude.cc's DcmToEuler and WrapPi, mc_statistics.cc's ErrorComponentsOf),
// W > 1 the errors of a lockstep group's W runs against one truth at once (the lane kernels,
// lockstep_ned_{baseline,avx2,avx512}.cc), so each operation exists once and every path gives
// the same bits.
// Arithmetic is lane-wise IEEE (-ffp-contract=off); atan2, asin and hypot are the engine's own
// (math/elementary_functions.h: the same bits on every machine), remainder the C library's (an
// exact operation, the same in every correct implementation), called per lane with the same
// arguments as the scalar code (lanes whose remainder would return its argument unchanged skip the
// call). As lanes/lane.h: internal linkage, no Eigen and no standard-library templates (a kernel
// file shares no inline code with the rest).
#pragma once

#include "lanes/lane.h"
#include "math/elementary_functions.h"

namespace driftlab::nav_error_lanes {

// What ErrorComponents needs of the truth at one epoch (NavErrorTruth, nav_state.h). Plain data
// without member initialisers (no inline constructor for a kernel file to emit).
struct TruthTerms {
  double lat_rad, lon_rad, h_m;
  double v_eb_n[3];
  double north_m, east_m, cos_L;  // NavEnvironment::PositionScale
  double euler_rad[3];            // roll, pitch, yaw
};

namespace {

using lanes::D;

constexpr double kPi = 3.14159265358979323846;  // M_PI
constexpr int kComponents = 11;                 // kNumErrorComponents (mc_statistics.h)

// f applied to each lane.
template <int W, typename F>
inline D<W> PerLane(D<W> x, F f) {
  if constexpr (W == 1) {
    return f(x);
  } else {
    for (int i = 0; i < W; ++i) x[i] = f(x[i]);
    return x;
  }
}
template <int W, typename F>
inline D<W> PerLane(D<W> x, D<W> y, F f) {
  if constexpr (W == 1) {
    return f(x, y);
  } else {
    for (int i = 0; i < W; ++i) x[i] = f(x[i], y[i]);
    return x;
  }
}

// remainder(x, 2 pi) as std::remainder: |x| <= pi (M_PI) returns x itself (x / 2pi is within
// [-1/2, 1/2], rounded to the even quotient 0), so only the other lanes call the library.
inline double RemainderTwoPi(double x) {
  if (x >= -kPi && x <= kPi) return x;
  return __builtin_remainder(x, 2.0 * kPi);
}
// The angle wrapped to (-pi, pi] (attitude.h WrapPi).
inline double WrapPiOf(double a) {
  // Already in (-pi, pi]: remainder would return it unchanged, so skip the library call.
  if (a > -kPi && a <= kPi) return a;
  double w = __builtin_remainder(a, 2.0 * kPi);
  if (w <= -kPi) w += 2.0 * kPi;
  return w;
}

// Position error N, E, D of an estimate (lat, lon, h) against the truth's, scaled at the truth
// (NavEnvironment::PositionScale: north_m, east_m, cos_L; first-order, Groves (2.119)); the
// longitude difference taken modulo 2 pi.
template <int W>
inline void PositionError(D<W> lat, D<W> lon, D<W> h, double truth_lat, double truth_lon,
                          double truth_h, double north_m, double east_m, double cos_L,
                          D<W> (&r)[3]) {
  const D<W> dL = lat - truth_lat;
  const D<W> dlambda = PerLane<W>(lon - truth_lon, [](double x) { return RemainderTwoPi(x); });
  const D<W> dh = h - truth_h;
  // Flat: cos_L = 1, a product that changes nothing.
  r[0] = dL * north_m;
  r[1] = dlambda * east_m * cos_L;
  r[2] = -dh;
}

// Roll, pitch, yaw of C_b_n from its elements (0,0), (1,0), (2,0), (2,1), (2,2)
// (Groves (2.17): the inverse of the Euler-to-DCM (2.22), pitch from the clamped (2,0)).
template <int W>
inline void EulerOfDcm(D<W> c00, D<W> c10, D<W> c20, D<W> c21, D<W> c22, D<W> (&euler)[3]) {
  euler[0] = PerLane<W>(c21, c22, [](double y, double x) { return elementary::Atan2(y, x); });
  euler[1] =
      -PerLane<W>(lanes::Clamp<W>(c20, -1.0, 1.0), [](double s) { return elementary::Asin(s); });
  euler[2] = PerLane<W>(c10, c00, [](double y, double x) { return elementary::Atan2(y, x); });
}

// Those five elements of C_b_n from the quaternion q_b_n = (w, x, y, z), with the operations of
// Eigen 3.4's QuaternionBase::toRotationMatrix (NavState::C_b_n).
template <int W>
inline void EulerOfQuaternion(D<W> w, D<W> x, D<W> y, D<W> z, D<W> (&euler)[3]) {
  const D<W> tx = 2.0 * x, ty = 2.0 * y, tz = 2.0 * z;
  const D<W> twx = tx * w, twy = ty * w, twz = tz * w;
  const D<W> txx = tx * x, txy = ty * x, txz = tz * x;
  const D<W> tyy = ty * y, tyz = tz * y, tzz = tz * z;
  EulerOfDcm<W>(1.0 - (tyy + tzz), txy + twz, txz - twy, tyz + twx, 1.0 - (txx + tyy), euler);
}

// Horizontal (hypot of N and E) and 3-D position error (Eigen 3.4's Vector3d::norm in the default
// x86-64 / arm64 build: sqrt of (x^2 + y^2) + z^2, its two-lane packet reduced first).
template <int W>
inline D<W> Horizontal(D<W> n, D<W> e) {
  return PerLane<W>(n, e, [](double a, double b) { return elementary::Hypot(a, b); });
}
template <int W>
inline D<W> Norm3(D<W> x, D<W> y, D<W> z) {
  return lanes::Sqrt<W>((x * x + y * y) + z * z);
}

// ErrorComponentsOf(ComputeNavError(env, estimate, truth)) for W estimates: out[c] is component c
// (ErrorComponent order: r N E D, v N E D, roll pitch yaw, horizontal, 3-D).
template <int W>
inline void ErrorComponents(const TruthTerms& t, D<W> lat, D<W> lon, D<W> h, const D<W> (&v)[3],
                            const D<W> (&q)[4], D<W> (&out)[kComponents]) {
  D<W> r[3];
  PositionError<W>(lat, lon, h, t.lat_rad, t.lon_rad, t.h_m, t.north_m, t.east_m, t.cos_L, r);
  D<W> euler[3];
  EulerOfQuaternion<W>(q[0], q[1], q[2], q[3], euler);
  for (int i = 0; i < 3; ++i) {
    out[i] = r[i];
    out[3 + i] = v[i] - t.v_eb_n[i];
    out[6 + i] = PerLane<W>(euler[i] - t.euler_rad[i], [](double a) { return WrapPiOf(a); });
  }
  out[9] = Horizontal<W>(r[0], r[1]);
  out[10] = Norm3<W>(r[0], r[1], r[2]);
}

}  // namespace
}  // namespace driftlab::nav_error_lanes
