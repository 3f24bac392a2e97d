#include "driftlab/earth.h"

#include <cmath>

#include "driftlab/elementary.h"
#include "earth/earth_lanes.h"
#include "math/elementary_functions.h"
#include "stats/nav_error_lanes.h"

namespace driftlab {

namespace {

// The engine's own sin and cos (math/elementary_functions.h): the lockstep kernels compute the same
// bits.
struct SinCosOf {
  double s, c;
  explicit SinCosOf(double x) { elementary::SinCos<1>(x, s, c); }
};
double Sin(double x) { return SinCosOf(x).s; }
double Cos(double x) { return SinCosOf(x).c; }

Vector3d ToVector(const vector_lanes::V3<1>& v) { return Vector3d(v.x, v.y, v.z); }
vector_lanes::V3<1> ToLanes(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

earth_lanes::Lat<1> LatOf(const NavEnvironment::Latitude& L) {
  return earth_lanes::LatOfSinCos<1>(L.L_rad, L.sin_L, L.cos_L);
}

// The Lat that earth_lanes' environment functions read: a flat environment reads none of it, so
// only WGS-84 computes sin, cos and the radii.
earth_lanes::Lat<1> LatFor(const EarthParams& e, double L_b) {
  if (e.flat) return {L_b, 0.0, 1.0, 0.0, 0.0};
  return earth_lanes::LatOf<1>(L_b);
}
earth_lanes::Lat<1> LatFor(const EarthParams& e, const NavEnvironment::Latitude& L) {
  if (e.flat) return {L.L_rad, L.sin_L, L.cos_L, 0.0, 0.0};
  return LatOf(L);
}

}  // namespace

double MeridianRadius(double L_b) { return earth_lanes::RadiiOfSin<1>(Sin(L_b)).R_N; }

double TransverseRadius(double L_b) { return earth_lanes::RadiiOfSin<1>(Sin(L_b)).R_E; }

double SomiglianaGravity(double L_b) { return earth_lanes::SomiglianaGravityOfSin<1>(Sin(L_b)); }

Vector3d GravityNed(double L_b, double h_b) {
  const SinCosOf L(L_b);
  return ToVector(earth_lanes::Wgs84Gravity<1>(L.s, L.c, h_b));
}

Vector3d EarthRateNed(double L_b) {
  const SinCosOf L(L_b);
  return ToVector(earth_lanes::Wgs84EarthRate<1>(L.s, L.c));
}

Vector3d TransportRateNed(double L_b, double h_b, const Vector3d& v_eb_n) {
  return ToVector(
      earth_lanes::Wgs84TransportRate<1>(earth_lanes::LatOf<1>(L_b), h_b, ToLanes(v_eb_n)));
}

Vector3d LlhToEcef(const Llh& llh) {
  const double R_E = TransverseRadius(llh.lat_rad);
  const double cL = Cos(llh.lat_rad), sL = Sin(llh.lat_rad);
  return Vector3d((R_E + llh.h_m) * cL * Cos(llh.lon_rad), (R_E + llh.h_m) * cL * Sin(llh.lon_rad),
                  ((1.0 - kWgs84Eccentricity2) * R_E + llh.h_m) * sL);
}

Llh EcefToLlh(const Vector3d& r_eb_e) {
  const double a = kWgs84SemiMajorAxis_m, b = kWgs84SemiMinorAxis_m, e2 = kWgs84Eccentricity2;
  const double p = math::Hypot(r_eb_e.x(), r_eb_e.y());
  const double z = r_eb_e.z();
  Llh llh;
  llh.lon_rad = math::Atan2(r_eb_e.y(), r_eb_e.x());
  if (p < 1e-9) {  // on the polar axis
    llh.lat_rad = z >= 0.0 ? M_PI / 2.0 : -M_PI / 2.0;
    llh.h_m = std::abs(z) - b;
    return llh;
  }
  // Bowring's initial guess (ep2 = second eccentricity squared), then fixed-point iteration
  // of L = atan((z + e^2 R_E sin L) / p), which converges quadratically from this start.
  const double ep2 = e2 / (1.0 - e2);
  const double u = math::Atan2(z * a, p * b);
  const double su = Sin(u), cu = Cos(u);
  double L = math::Atan2(z + ep2 * b * (su * su * su), p - e2 * a * (cu * cu * cu));
  for (int i = 0; i < 8; ++i) {
    const double R_E = TransverseRadius(L);
    const double L_next = math::Atan2(z + e2 * R_E * Sin(L), p);
    const bool done = std::abs(L_next - L) < 1e-15;
    L = L_next;
    if (done) break;
  }
  llh.lat_rad = L;
  const double R_E = TransverseRadius(L);
  // Height along the ellipsoid normal: h = p cos L + z sin L - a^2 / R_E (the distance of r_eb_e
  // from the ellipsoid measured on the normal at L; first-order insensitive to an error in L,
  // unlike p / cos L - R_E, whose error grows as R tan L dL towards the poles). Bowring, "The
  // accuracy of geodetic latitude and height equations", Survey Review 28 (1985) 202-206.
  double sL, cL;
  math::SinCos(L, &sL, &cL);
  llh.h_m = (p * cL + z * sL) - a * a / R_E;
  return llh;
}

Matrix3d EcefToNedDcm(double L_b, double lambda_b) {
  const double sL = Sin(L_b), cL = Cos(L_b);
  const double sl = Sin(lambda_b), cl = Cos(lambda_b);
  Matrix3d C_e_n;
  C_e_n << -sL * cl, -sL * sl, cL,  //
      -sl, cl, 0.0,                 //
      -cL * cl, -cL * sl, -sL;
  return C_e_n;
}

Vector3d LlhToNed(const Llh& p, const Llh& ref) {
  return EcefToNedDcm(ref.lat_rad, ref.lon_rad) * (LlhToEcef(p) - LlhToEcef(ref));
}

Llh NedToLlh(const Vector3d& r_n, const Llh& ref) {
  const Matrix3d C_n_e = EcefToNedDcm(ref.lat_rad, ref.lon_rad).transpose();
  return EcefToLlh(LlhToEcef(ref) + C_n_e * r_n);
}

NavEnvironment NavEnvironment::Wgs84() { return NavEnvironment(); }

NavEnvironment NavEnvironment::Flat(const Llh& reference, double gravity_m_per_s2) {
  NavEnvironment env;
  env.params_.flat = 1;
  // Radii frozen at the reference point; for the flat frame they only scale metres to the
  // latitude/longitude bookkeeping and back, so any positive constant gives the same metres.
  env.params_.flat_R_N_m = MeridianRadius(reference.lat_rad) + reference.h_m;
  env.params_.flat_R_E_m = TransverseRadius(reference.lat_rad) + reference.h_m;
  env.params_.flat_gravity_m_per_s2 = gravity_m_per_s2;
  return env;
}

double NavEnvironment::MeridianRadiusAt(double L_b) const {
  return params_.flat ? params_.flat_R_N_m : MeridianRadius(L_b);
}

double NavEnvironment::TransverseRadiusAt(double L_b) const {
  return params_.flat ? params_.flat_R_E_m : TransverseRadius(L_b);
}

// The environment's rates and gravity are earth_lanes' at one lane.

Vector3d NavEnvironment::Gravity(double L_b, double h_b) const {
  const earth_lanes::Lat<1> L = LatFor(params_, L_b);
  return ToVector(earth_lanes::Gravity<1>(params_, L.s, L.c, h_b));
}

Vector3d NavEnvironment::EarthRate(double L_b) const {
  const earth_lanes::Lat<1> L = LatFor(params_, L_b);
  return ToVector(earth_lanes::EarthRate<1>(params_, L.s, L.c));
}

Vector3d NavEnvironment::TransportRate(double L_b, double h_b, const Vector3d& v_eb_n) const {
  return ToVector(
      earth_lanes::TransportRate<1>(params_, LatFor(params_, L_b), h_b, ToLanes(v_eb_n)));
}

NavEnvironment::Latitude NavEnvironment::Latitude::Of(double L_rad) {
  Latitude l;
  l.L_rad = L_rad;
  elementary::SinCos<1>(L_rad, l.sin_L, l.cos_L);
  return l;
}

NavEnvironment::Latitude NavEnvironment::Latitude::Near(const Latitude& known, double L_rad) {
  Latitude l;
  l.L_rad = L_rad;
  elementary::SinCosNear<1>(L_rad, known.L_rad, known.sin_L, known.cos_L, l.sin_L, l.cos_L);
  return l;
}

NavEnvironment::PointRates NavEnvironment::AtPoint(double L_b, double h_b,
                                                   const Vector3d& v_eb_n) const {
  return AtPoint(Latitude::Of(L_b), h_b, v_eb_n);
}

NavEnvironment::PointRates NavEnvironment::AtPoint(const Latitude& lat, double h_b,
                                                   const Vector3d& v_eb_n) const {
  const earth_lanes::Lat<1> L = LatFor(params_, lat);
  return {ToVector(earth_lanes::EarthRate<1>(params_, L.s, L.c)),
          ToVector(earth_lanes::TransportRate<1>(params_, L, h_b, ToLanes(v_eb_n))),
          ToVector(earth_lanes::Gravity<1>(params_, L.s, L.c, h_b))};
}

Vector3d NavEnvironment::LlhRate(double L_b, double h_b, const Vector3d& v_eb_n) const {
  return ToVector(earth_lanes::LlhRate<1>(params_, LatFor(params_, L_b), h_b, ToLanes(v_eb_n)));
}

Vector3d NavEnvironment::LlhRate(const Latitude& lat, double h_b, const Vector3d& v_eb_n) const {
  return ToVector(earth_lanes::LlhRate<1>(params_, LatFor(params_, lat), h_b, ToLanes(v_eb_n)));
}

Vector3d NavEnvironment::PositionErrorNed(const Llh& estimate, const Llh& truth) const {
  return PositionErrorNed(estimate, truth, PositionScaleAt(truth));
}

NavEnvironment::PositionScale NavEnvironment::PositionScaleAt(const Llh& truth) const {
  if (params_.flat) return {params_.flat_R_N_m, params_.flat_R_E_m, 1.0};
  // First-order curvilinear-to-metre scaling, Groves (2.119); exact to ~1e-7 relative for the
  // position errors of interest (< 100 km).
  return {MeridianRadius(truth.lat_rad) + truth.h_m, TransverseRadius(truth.lat_rad) + truth.h_m,
          Cos(truth.lat_rad)};
}

Vector3d NavEnvironment::PositionErrorNed(const Llh& estimate, const Llh& truth,
                                          const PositionScale& scale) const {
  double r[3];  // the lockstep kernels' code at one lane (nav_error_lanes.h)
  nav_error_lanes::PositionError<1>(estimate.lat_rad, estimate.lon_rad, estimate.h_m, truth.lat_rad,
                                    truth.lon_rad, truth.h_m, scale.north_m, scale.east_m,
                                    scale.cos_L, r);
  return Vector3d(r[0], r[1], r[2]);
}

}  // namespace driftlab
