// Earth model: WGS-84 ellipsoid, radii of curvature, normal gravity, Earth and transport rates,
// and conversions between geodetic (LLH), Earth-centred Earth-fixed (ECEF) and local NED
// coordinates. Also the flat local frame with constant gravity used by seed 000.
//
// Frames: e = ECEF, n = local-level NED at the body, b = body (forward-right-down).
// Units: SI (metres, seconds, radians). Latitude L_b, longitude lambda_b, height h_b above the
// ellipsoid.
//
// The WGS-84 constants are driftlab/earth_constants.h's; the radii, gravity and rates are computed
// by the Earth functions written over the lane width (engine/src/earth/earth_lanes.h), which the
// lockstep runs use at W lanes, so every path sees the same physics, to the bit.
//
// References: NIMA TR8350.2 (WGS-84, 3rd ed., 2000); Groves, "Principles of GNSS, Inertial, and
// Multisensor Integrated Navigation Systems", 2nd ed. (2013), sections 2.4 and 2.4.7.
#pragma once

#include <Eigen/Core>

#include "driftlab/earth_constants.h"

namespace driftlab {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Meridian radius of curvature R_N(L) = a (1 - e^2) / (1 - e^2 sin^2 L)^(3/2). Groves (2.105).
double MeridianRadius(double L_b);
// Transverse (prime-vertical) radius of curvature R_E(L) = a / sqrt(1 - e^2 sin^2 L). Groves
// (2.106).
double TransverseRadius(double L_b);

// Magnitude of normal gravity on the ellipsoid surface, Somigliana's closed formula
// gamma_0(L) = gamma_e (1 + k sin^2 L) / sqrt(1 - e^2 sin^2 L), k = b gamma_p / (a gamma_e) - 1.
// Groves (2.134).
double SomiglianaGravity(double L_b);

// Gravity (gravitation plus centrifugal) resolved in NED at latitude L_b and height h_b:
//   g_D = gamma_0(L) [1 - 2/a (1 + f (1 - 2 sin^2 L) + omega_ie^2 a^2 b / mu) h + 3 h^2 / a^2]
//   g_N = -8.08e-9 h sin 2L, g_E = 0.
// Groves (2.139)-(2.140). Valid for heights well below 10 km of ellipsoid (free-air expansion).
Vector3d GravityNed(double L_b, double h_b);

// Earth rotation rate resolved in NED: omega_ie_n = omega_ie [cos L, 0, -sin L]^T. Groves (5.41).
Vector3d EarthRateNed(double L_b);

// Transport rate, the turn rate of NED with respect to ECEF caused by motion over the curved
// Earth: omega_en_n = [v_E/(R_E+h), -v_N/(R_N+h), -v_E tan L/(R_E+h)]^T. Groves (5.44).
Vector3d TransportRateNed(double L_b, double h_b, const Vector3d& v_eb_n);

// Geodetic latitude, longitude, height.
struct Llh {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double h_m = 0.0;
};

// Geodetic to ECEF position. Groves (2.112).
Vector3d LlhToEcef(const Llh& llh);
// ECEF position to geodetic; iterated to machine precision (converges in <= 6 iterations for
// any point above -1000 km of height). Groves section 2.4.2, Bowring initial guess.
Llh EcefToLlh(const Vector3d& r_eb_e);
// Rotation from ECEF to local NED at (L, lambda). Groves (2.150).
Matrix3d EcefToNedDcm(double L_b, double lambda_b);  // C_e_n
// NED displacement of point `p` relative to the reference point `ref`, through ECEF
// (exact, no small-distance approximation).
Vector3d LlhToNed(const Llh& p, const Llh& ref);
// Inverse of LlhToNed.
Llh NedToLlh(const Vector3d& r_n, const Llh& ref);

// Earth model selected for a job.
enum class EarthModel {
  kWgs84,  // ellipsoid, normal gravity with height, Earth rotation
  kFlat,   // seed 000: flat local frame, constant gravity, no Earth rotation or transport rate
};

// Navigation-frame environment queried by the generator and the mechanizations, so that both see
// exactly the same physics. For kFlat, the geodetic coordinates map to metres through constant
// radii frozen at the reference point (a local tangent plane), gravity is
// [0, 0, gravity_m_per_s2] and the rotation rates are zero.
class NavEnvironment {
 public:
  static NavEnvironment Wgs84();
  static NavEnvironment Flat(const Llh& reference, double gravity_m_per_s2);

  EarthModel model() const { return params_.flat ? EarthModel::kFlat : EarthModel::kWgs84; }
  // The environment as plain data (the lane code's view, earth_constants.h).
  const EarthParams& params() const { return params_; }
  // Radii used for d(L)/dt = v_N / (R_N + h) and d(lambda)/dt = v_E / ((R_E + h) cos L).
  double MeridianRadiusAt(double L_b) const;
  double TransverseRadiusAt(double L_b) const;
  Vector3d Gravity(double L_b, double h_b) const;                                // g_b_n
  Vector3d EarthRate(double L_b) const;                                          // omega_ie_n
  Vector3d TransportRate(double L_b, double h_b, const Vector3d& v_eb_n) const;  // omega_en_n
  // A latitude with its sine and cosine, for code that evaluates the Earth model at several
  // nearby latitudes (the trajectory generator's sub-step): Near() takes them from a known one by
  // the angle-sum rotation (elementary::SinCosNear, within ~2 ulp of a full sin/cos).
  struct Latitude {
    double L_rad = 0.0, sin_L = 0.0, cos_L = 1.0;
    static Latitude Of(double L_rad);
    static Latitude Near(const Latitude& known, double L_rad);
  };
  // EarthRate, TransportRate and Gravity at one point, the same values, with one sin/cos of L.
  struct PointRates {
    Vector3d omega_ie_n, omega_en_n, g_b_n;
  };
  PointRates AtPoint(double L_b, double h_b, const Vector3d& v_eb_n) const;
  PointRates AtPoint(const Latitude& L, double h_b, const Vector3d& v_eb_n) const;
  // Rate of change of (L, lambda, h) for NED velocity v_eb_n. Groves (2.111).
  Vector3d LlhRate(double L_b, double h_b, const Vector3d& v_eb_n) const;
  Vector3d LlhRate(const Latitude& L, double h_b, const Vector3d& v_eb_n) const;
  // Position error of `estimate` relative to `truth`, in metres along N, E, D at the truth point,
  // using the curvilinear-to-metre scaling of this environment.
  Vector3d PositionErrorNed(const Llh& estimate, const Llh& truth) const;
  // That scaling at a truth point, for many estimates against one truth (the same operations as
  // PositionErrorNed(estimate, truth), so the same bits): dL (R_N + h), dlambda (R_E + h) cos L.
  struct PositionScale {
    double north_m = 0.0, east_m = 0.0, cos_L = 1.0;  // flat: its radii and 1
  };
  PositionScale PositionScaleAt(const Llh& truth) const;
  Vector3d PositionErrorNed(const Llh& estimate, const Llh& truth,
                            const PositionScale& scale) const;

 private:
  EarthParams params_;  // WGS-84 by default
};

}  // namespace driftlab
