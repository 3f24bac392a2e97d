// The Earth model written once over the lane width W (lanes/lane.h): WGS-84 radii of curvature,
// normal gravity with height, Earth rate, transport rate and the rate of (L, lambda, h), and the
// navigation environment (flat frame or WGS-84, EarthParams) on top of them. W = 1 is the scalar
// Earth model (earth.cc: the functions of earth.h and NavEnvironment call these); W > 1 the
// lockstep kernels' W runs at once (the mechanization step, ins/ned_step.h). The constants are the
// one WGS-84 set of driftlab/earth_constants.h.
//
// sin L and cos L come from the caller (a latitude's are computed once and reused: Lat below), so
// each formula here takes them; tan L is sin L / cos L. The order of operations is the scalar
// model's as documented in earth.h, the same for every W.
// A lane header (lanes/lane.h): internal linkage, no Eigen or standard-library templates.
//
// References: NIMA TR8350.2 (WGS-84, 3rd ed., 2000); Groves, "Principles of GNSS, Inertial, and
// Multisensor Integrated Navigation Systems", 2nd ed. (2013), sections 2.4 and 5.4.
#pragma once

#include "driftlab/earth_constants.h"
#include "lanes/lane.h"
#include "math/elementary_functions.h"
#include "math/vector_lanes.h"

namespace driftlab::earth_lanes {
namespace {

using lanes::D;
using vector_lanes::V3;

constexpr double kA = kWgs84SemiMajorAxis_m;
constexpr double kF = kWgs84Flattening;
constexpr double kE2 = kWgs84Eccentricity2;
constexpr double kB = kWgs84SemiMinorAxis_m;
constexpr double kOmega = kWgs84EarthRate_rad_per_s;
constexpr double kGM = kWgs84GM_m3_per_s2;
constexpr double kGammaE = kWgs84GammaEquator_m_per_s2;
constexpr double kGammaP = kWgs84GammaPole_m_per_s2;

// The two radii of curvature at a latitude of sine s, from one square root:
//   R_N = a (1 - e^2) / (1 - e^2 sin^2 L)^(3/2)      Groves (2.105)
//   R_E = a / sqrt(1 - e^2 sin^2 L)                   Groves (2.106)
template <int W>
struct Radii {
  D<W> R_N, R_E;
};
template <int W>
inline Radii<W> RadiiOfSin(D<W> s) {
  const D<W> d = 1.0 - kE2 * s * s;
  const D<W> sqrt_d = lanes::Sqrt<W>(d);
  return {kA * (1.0 - kE2) / (d * sqrt_d), kA / sqrt_d};
}

// A latitude with its sine, cosine and radii of curvature, computed once and reused.
template <int W>
struct Lat {
  D<W> L, s, c;
  D<W> R_N, R_E;  // RadiiOfSin(s)
};
template <int W>
inline Lat<W> LatOfSinCos(D<W> L, D<W> s, D<W> c) {
  const Radii<W> r = RadiiOfSin<W>(s);
  return {L, s, c, r.R_N, r.R_E};
}
template <int W>
inline Lat<W> LatOf(D<W> L) {
  D<W> s, c;
  elementary::SinCos<W>(L, s, c);
  return LatOfSinCos<W>(L, s, c);
}
// The Lat of a latitude L near one already known (a step's midpoint and end from its start;
// |L - base.L| ~ v dt / R, 5e-7 rad for 300 m/s at 100 Hz), its sine and cosine by the angle-sum
// rotation (elementary::SinCosNear, within ~2 ulp of a full sin/cos), so that a mechanization step
// needs one full sin/cos of latitude instead of five.
template <int W>
inline Lat<W> LatNear(const Lat<W>& base, D<W> L) {
  D<W> s, c;
  elementary::SinCosNear<W>(L, base.L, base.s, base.c, s, c);
  return LatOfSinCos<W>(L, s, c);
}

// Magnitude of normal gravity on the ellipsoid, Somigliana's closed formula
//   gamma_0(L) = gamma_e (1 + k sin^2 L) / sqrt(1 - e^2 sin^2 L),  k = b gamma_p / (a gamma_e) - 1.
// Groves (2.134), NIMA TR8350.2 (4-1).
template <int W>
inline D<W> SomiglianaGravityOfSin(D<W> s) {
  constexpr double k = kB * kGammaP / (kA * kGammaE) - 1.0;
  const D<W> s2 = s * s;
  return kGammaE * (1.0 + k * s2) / lanes::Sqrt<W>(1.0 - kE2 * s2);
}

// WGS-84 gravity (gravitation plus centrifugal) resolved in NED at height h:
//   g_D = gamma_0(L) [1 - 2/a (1 + f (1 - 2 sin^2 L) + m) h + 3 h^2 / a^2]
//   g_N = -8.08e-9 h sin 2L,  g_E = 0;   sin 2L = 2 sin L cos L
// with m = omega_ie^2 a^2 b / mu, the ratio of centrifugal to gravitational acceleration at the
// equator (NIMA TR8350.2 table 3.3: 0.00344978650684). Groves (2.139)-(2.140); valid for heights
// well below 10 km of the ellipsoid (free-air expansion).
template <int W>
inline V3<W> Wgs84Gravity(D<W> s, D<W> c, D<W> h) {
  constexpr double m = kOmega * kOmega * kA * kA * kB / kGM;
  const D<W> s2 = s * s;
  const D<W> g0 = SomiglianaGravityOfSin<W>(s);
  const D<W> g_D =
      g0 * (1.0 - 2.0 / kA * (1.0 + kF * (1.0 - 2.0 * s2) + m) * h + 3.0 * h * h / (kA * kA));
  const D<W> g_N = -8.08e-9 * h * (2.0 * s * c);
  return {g_N, lanes::Splat<W>(0.0), g_D};
}

// Earth rotation rate resolved in NED: omega_ie_n = omega_ie [cos L, 0, -sin L]. Groves (5.41).
template <int W>
inline V3<W> Wgs84EarthRate(D<W> s, D<W> c) {
  return {kOmega * c, lanes::Splat<W>(0.0), -kOmega * s};
}

// Transport rate, the turn rate of NED with respect to the Earth from motion over the ellipsoid:
//   omega_en_n = [v_E / (R_E + h), -v_N / (R_N + h), -v_E tan L / (R_E + h)]     Groves (5.44)
template <int W>
inline V3<W> Wgs84TransportRate(const Lat<W>& l, D<W> h, const V3<W>& v) {
  const D<W> R_E = l.R_E + h;
  const D<W> R_N = l.R_N + h;
  return {v.y / R_E, -v.x / R_N, -v.y * (l.s / l.c) / R_E};
}

// Rate of (L, lambda, h) for the NED velocity v: [v_N / (R_N + h), v_E / ((R_E + h) cos L), -v_D].
// Groves (2.111).
template <int W>
inline V3<W> Wgs84LlhRate(const Lat<W>& l, D<W> h, const V3<W>& v) {
  return {v.x / (l.R_N + h), v.y / ((l.R_E + h) * l.c), -v.z};
}

// ---- The navigation environment: WGS-84, or the flat frame (constant radii and gravity, no
// rotation rates; the radii only scale metres to latitude and longitude, and h plays no part in
// that scaling).

template <int W>
inline V3<W> EarthRate(const EarthParams& e, D<W> s, D<W> c) {
  if (e.flat) return vector_lanes::Splat3<W>(0.0, 0.0, 0.0);
  return Wgs84EarthRate<W>(s, c);
}
template <int W>
inline V3<W> TransportRate(const EarthParams& e, const Lat<W>& l, D<W> h, const V3<W>& v) {
  if (e.flat) return vector_lanes::Splat3<W>(0.0, 0.0, 0.0);
  return Wgs84TransportRate<W>(l, h, v);
}
template <int W>
inline V3<W> Gravity(const EarthParams& e, D<W> s, D<W> c, D<W> h) {
  if (e.flat) return vector_lanes::Splat3<W>(0.0, 0.0, e.flat_gravity_m_per_s2);
  return Wgs84Gravity<W>(s, c, h);
}
// Flat: no Lat is read (the caller may pass one with only L set).
template <int W>
inline V3<W> LlhRate(const EarthParams& e, const Lat<W>& l, D<W> h, const V3<W>& v) {
  if (e.flat) return {v.x / e.flat_R_N_m, v.y / e.flat_R_E_m, -v.z};
  return Wgs84LlhRate<W>(l, h, v);
}

}  // namespace
}  // namespace driftlab::earth_lanes
