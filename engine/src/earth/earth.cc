#include "driftlab/earth.h"

#include <cmath>

#include "driftlab/elementary.h"
#include "math/elementary_functions.h"
#include "stats/nav_error_lanes.h"

namespace driftlab {

namespace {

// The engine's own sin and cos (math/elementary_functions.h): the lockstep kernels compute the same
// bits.
struct SinCosOf {
  double s, c;
  explicit SinCosOf(double x) { elementary::SinCos<1>(x, s, c); }
  explicit SinCosOf(const NavEnvironment::Latitude& L) : s(L.sin_L), c(L.cos_L) {}
};
double Sin(double x) { return SinCosOf(x).s; }
double Cos(double x) { return SinCosOf(x).c; }

// The formulas below take sin L, computed once per call of the public functions.
double MeridianRadiusOfSin(double s) {
  const double d = 1.0 - kWgs84Eccentricity2 * s * s;
  return kWgs84SemiMajorAxis_m * (1.0 - kWgs84Eccentricity2) / (d * std::sqrt(d));
}

double TransverseRadiusOfSin(double s) {
  return kWgs84SemiMajorAxis_m / std::sqrt(1.0 - kWgs84Eccentricity2 * s * s);
}

// Both radii of curvature from one square root: the operations of MeridianRadiusOfSin and
// TransverseRadiusOfSin (the same d and sqrt(d)), so the same bits.
struct RadiiOfSin {
  double R_N, R_E;
  explicit RadiiOfSin(double s) {
    const double d = 1.0 - kWgs84Eccentricity2 * s * s;
    const double sqrt_d = std::sqrt(d);
    R_N = kWgs84SemiMajorAxis_m * (1.0 - kWgs84Eccentricity2) / (d * sqrt_d);
    R_E = kWgs84SemiMajorAxis_m / sqrt_d;
  }
};

double SomiglianaGravityOfSin(double s) {
  // k = b gamma_p / (a gamma_e) - 1, Groves (2.134) / NIMA TR8350.2 (4-1).
  const double k = kWgs84SemiMinorAxis_m * kWgs84GammaPole_m_per_s2 /
                       (kWgs84SemiMajorAxis_m * kWgs84GammaEquator_m_per_s2) -
                   1.0;
  const double s2 = s * s;
  return kWgs84GammaEquator_m_per_s2 * (1.0 + k * s2) / std::sqrt(1.0 - kWgs84Eccentricity2 * s2);
}

}  // namespace

double MeridianRadius(double L_b) { return MeridianRadiusOfSin(Sin(L_b)); }

double TransverseRadius(double L_b) { return TransverseRadiusOfSin(Sin(L_b)); }

double SomiglianaGravity(double L_b) { return SomiglianaGravityOfSin(Sin(L_b)); }

namespace {

// GravityNed, EarthRateNed and TransportRateNed of a latitude's sin and cos
// (NavEnvironment::AtPoint computes those once for all three).
Vector3d GravityNedOf(const SinCosOf& sc, double h_b) {
  const double a = kWgs84SemiMajorAxis_m;
  const double f = kWgs84Flattening;
  const double s = sc.s;
  const double s2 = s * s;
  // m = omega_ie^2 a^2 b / mu, the ratio of centrifugal to gravitational acceleration at the
  // equator (NIMA TR8350.2 table 3.3: 0.00344978650684).
  const double m = kWgs84EarthRate_rad_per_s * kWgs84EarthRate_rad_per_s * a * a *
                   kWgs84SemiMinorAxis_m / kWgs84GM_m3_per_s2;
  const double g0 = SomiglianaGravityOfSin(s);
  const double g_D =
      g0 * (1.0 - 2.0 / a * (1.0 + f * (1.0 - 2.0 * s2) + m) * h_b + 3.0 * h_b * h_b / (a * a));
  const double g_N = -8.08e-9 * h_b * (2.0 * s * sc.c);  // sin 2L = 2 sin L cos L
  return Vector3d(g_N, 0.0, g_D);
}

Vector3d EarthRateNedOf(const SinCosOf& L) {
  return Vector3d(kWgs84EarthRate_rad_per_s * L.c, 0.0, -kWgs84EarthRate_rad_per_s * L.s);
}

Vector3d TransportRateNedOf(const SinCosOf& L, double h_b, const Vector3d& v_eb_n) {
  const RadiiOfSin radii(L.s);
  const double R_E = radii.R_E + h_b;
  const double R_N = radii.R_N + h_b;
  return Vector3d(v_eb_n.y() / R_E, -v_eb_n.x() / R_N, -v_eb_n.y() * (L.s / L.c) / R_E);
}

}  // namespace

Vector3d GravityNed(double L_b, double h_b) { return GravityNedOf(SinCosOf(L_b), h_b); }

Vector3d EarthRateNed(double L_b) { return EarthRateNedOf(SinCosOf(L_b)); }

Vector3d TransportRateNed(double L_b, double h_b, const Vector3d& v_eb_n) {
  return TransportRateNedOf(SinCosOf(L_b), h_b, v_eb_n);
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
  env.model_ = EarthModel::kFlat;
  // Radii frozen at the reference point; for the flat frame they only scale metres to the
  // latitude/longitude bookkeeping and back, so any positive constant gives the same metres.
  env.flat_R_N_m_ = MeridianRadius(reference.lat_rad) + reference.h_m;
  env.flat_R_E_m_ = TransverseRadius(reference.lat_rad) + reference.h_m;
  env.flat_gravity_m_per_s2_ = gravity_m_per_s2;
  return env;
}

double NavEnvironment::MeridianRadiusAt(double L_b) const {
  return model_ == EarthModel::kFlat ? flat_R_N_m_ : MeridianRadius(L_b);
}

double NavEnvironment::TransverseRadiusAt(double L_b) const {
  return model_ == EarthModel::kFlat ? flat_R_E_m_ : TransverseRadius(L_b);
}

Vector3d NavEnvironment::Gravity(double L_b, double h_b) const {
  if (model_ == EarthModel::kFlat) return Vector3d(0.0, 0.0, flat_gravity_m_per_s2_);
  return GravityNed(L_b, h_b);
}

Vector3d NavEnvironment::EarthRate(double L_b) const {
  if (model_ == EarthModel::kFlat) return Vector3d::Zero();
  return EarthRateNed(L_b);
}

Vector3d NavEnvironment::TransportRate(double L_b, double h_b, const Vector3d& v_eb_n) const {
  if (model_ == EarthModel::kFlat) return Vector3d::Zero();
  return TransportRateNed(L_b, h_b, v_eb_n);
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
  if (model_ == EarthModel::kFlat) {
    return {Vector3d::Zero(), Vector3d::Zero(), Vector3d(0.0, 0.0, flat_gravity_m_per_s2_)};
  }
  const SinCosOf L(lat);
  return {EarthRateNedOf(L), TransportRateNedOf(L, h_b, v_eb_n), GravityNedOf(L, h_b)};
}

Vector3d NavEnvironment::LlhRate(double L_b, double h_b, const Vector3d& v_eb_n) const {
  if (model_ == EarthModel::kFlat) {
    // Flat frame: h plays no part in the metre scaling and there is no convergence of meridians.
    return Vector3d(v_eb_n.x() / flat_R_N_m_, v_eb_n.y() / flat_R_E_m_, -v_eb_n.z());
  }
  return LlhRate(Latitude::Of(L_b), h_b, v_eb_n);
}

Vector3d NavEnvironment::LlhRate(const Latitude& lat, double h_b, const Vector3d& v_eb_n) const {
  if (model_ == EarthModel::kFlat) {
    return Vector3d(v_eb_n.x() / flat_R_N_m_, v_eb_n.y() / flat_R_E_m_, -v_eb_n.z());
  }
  const SinCosOf L(lat);
  const RadiiOfSin radii(L.s);
  return Vector3d(v_eb_n.x() / (radii.R_N + h_b), v_eb_n.y() / ((radii.R_E + h_b) * L.c),
                  -v_eb_n.z());
}

Vector3d NavEnvironment::PositionErrorNed(const Llh& estimate, const Llh& truth) const {
  return PositionErrorNed(estimate, truth, PositionScaleAt(truth));
}

NavEnvironment::PositionScale NavEnvironment::PositionScaleAt(const Llh& truth) const {
  if (model_ == EarthModel::kFlat) return {flat_R_N_m_, flat_R_E_m_, 1.0};
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
