// Earth model against published WGS-84 reference values and exact geometric identities.
#include "driftlab/earth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

namespace driftlab {
namespace {

TEST(EarthTest, NormalGravityAtEquatorAndPoleMatchesNimaTr8350) {
  // NIMA TR8350.2 (2000) table 3.4: gamma_e = 9.7803253359, gamma_p = 9.8321849378 m/s^2.
  // Tolerance: half a unit of the last printed digit (5e-11) plus rounding of the closed formula.
  EXPECT_NEAR(SomiglianaGravity(0.0), 9.7803253359, 6e-11);
  EXPECT_NEAR(SomiglianaGravity(90.0 * kDeg), 9.8321849378, 6e-11);
  EXPECT_NEAR(SomiglianaGravity(-90.0 * kDeg), 9.8321849378, 6e-11);
  EXPECT_NEAR(GravityNed(0.0, 0.0).z(), 9.7803253359, 6e-11);
}

TEST(EarthTest, NormalGravityAt45DegMatchesInternationalGravityFormula1980) {
  // GRS80 international gravity formula (Moritz, "Geodetic Reference System 1980", Bull. Geod.
  // 54, 1980): gamma = 9.780327 (1 + 0.0053024 sin^2 L - 0.0000058 sin^2 2L) m/s^2.
  // Tolerance 1e-5 m/s^2: the series' truncation (~1e-6) plus the GRS80-WGS84 difference of
  // gamma_e (1.4e-6) and the 7-digit rounding of 9.780327 (5e-7), with margin.
  const double s2 = std::pow(std::sin(45.0 * kDeg), 2);
  const double s2_2 = std::pow(std::sin(90.0 * kDeg), 2);
  const double gamma_1980 = 9.780327 * (1.0 + 0.0053024 * s2 - 0.0000058 * s2_2);
  EXPECT_NEAR(SomiglianaGravity(45.0 * kDeg), gamma_1980, 1e-5);
}

TEST(EarthTest, RadiiOfCurvatureAt45DegMatchPublishedDegreeLengths) {
  // Published lengths of one degree on WGS-84 (Wikipedia "Latitude", section "Length of a degree
  // of latitude"; series m1..m4, p1..p3 from
  // https://en.wikipedia.org/wiki/Geographic_coordinate_system and
  // gis.stackexchange.com/questions/75528): at 45 deg,
  //   degree of latitude  = 111132.92 - 559.82 cos 90 + 1.175 cos 180 - 0.0023 cos 270 = 111131.745
  //   m degree of longitude = 111412.84 cos 45 - 93.5 cos 135 + 0.118 cos 225           = 78846.81
  //   m
  // R_N = latitude degree * 180/pi; R_E cos L = longitude degree * 180/pi.
  // Tolerance: the series agree with the exact ellipsoid to 0.6 ppm (gis.stackexchange 75528),
  // i.e. 0.07 m per degree -> 4 m in radius; we use 5 m.
  const double L = 45.0 * kDeg;
  const double lat_degree_m =
      111132.92 - 559.82 * std::cos(2 * L) + 1.175 * std::cos(4 * L) - 0.0023 * std::cos(6 * L);
  const double lon_degree_m =
      111412.84 * std::cos(L) - 93.5 * std::cos(3 * L) + 0.118 * std::cos(5 * L);
  EXPECT_NEAR(MeridianRadius(L), lat_degree_m / kDeg, 5.0);
  EXPECT_NEAR(TransverseRadius(L) * std::cos(L), lon_degree_m / kDeg, 5.0);
  // MathWorks Mapping Toolbox documentation, rcurve example (WGS-84, 45 deg, km, printed to
  // 5 significant digits): transverse 6.3888e3 km, meridian 6.3674e3 km. Tolerance half a digit.
  EXPECT_NEAR(TransverseRadius(L), 6388.8e3, 50.0);
  EXPECT_NEAR(MeridianRadius(L), 6367.4e3, 50.0);
  // Exact identities: R_N(0) = a (1 - e^2), R_E(0) = a, R_N(90) = R_E(90) = a^2 / b. Rounding only.
  EXPECT_NEAR(MeridianRadius(0.0), kWgs84SemiMajorAxis_m * (1.0 - kWgs84Eccentricity2), 1e-8);
  EXPECT_NEAR(TransverseRadius(0.0), kWgs84SemiMajorAxis_m, 1e-8);
  const double polar = kWgs84SemiMajorAxis_m * kWgs84SemiMajorAxis_m / kWgs84SemiMinorAxis_m;
  EXPECT_NEAR(MeridianRadius(M_PI / 2), polar, 1e-6);
  EXPECT_NEAR(TransverseRadius(M_PI / 2), polar, 1e-6);
}

TEST(EarthTest, FreeAirGradientAtEquatorIsAbout3086MicroGalPerMetre) {
  // Conventional free-air gradient -0.3086 mGal/m = -3.086e-6 s^-2 (Heiskanen & Moritz 1967,
  // "Physical Geodesy", 2-124: -2 gamma / a (1 + f + m - 2 f sin^2 L)). At the equator the
  // closed form gives -3.0877e-6; the conventional value is a latitude mean, 0.05 % away.
  // Tolerance 0.1 % of the gradient. Central difference over +-100 m: the h^2 term cancels.
  const double dh = 100.0;
  const double gradient = (GravityNed(0.0, dh).z() - GravityNed(0.0, -dh).z()) / (2.0 * dh);
  EXPECT_NEAR(gradient, -3.086e-6, 3.1e-9);
}

TEST(EarthTest, LlhEcefRoundTripIsExactToNanometres) {
  // EcefToLlh iterates to machine precision, so a round trip is limited by the resolution of the
  // ECEF doubles themselves: near 6.4e6 m they are 9.3e-10 m apart, and LlhToEcef, the height
  // formula and the iteration each round. Bound: 4 ulp = 4e-9 m in height, north and east and for
  // the ECEF vector. (1e-9 m is below the resolution of ECEF coordinates; on a 0.5-degree grid the
  // worst height error is 2.8e-9 m = 3 ulp, for any algorithm working in doubles.)
  for (double lat_deg = -90.0; lat_deg <= 90.0; lat_deg += 0.5) {
    for (double lon_deg = -180.0; lon_deg < 180.0; lon_deg += 15.0) {
      for (double h : {-500.0, 0.0, 1000.0, 1.0e4, 1.0e5}) {
        const Llh p{lat_deg * kDeg, lon_deg * kDeg, h};
        const Vector3d r = LlhToEcef(p);
        const Llh q = EcefToLlh(r);
        EXPECT_NEAR(q.h_m, h, 4e-9) << lat_deg << " " << lon_deg << " " << h;
        EXPECT_NEAR(q.lat_rad * (MeridianRadius(p.lat_rad) + h),
                    p.lat_rad * (MeridianRadius(p.lat_rad) + h), 4e-9)
            << lat_deg << " " << lon_deg << " " << h;
        const double east_scale_m = (TransverseRadius(p.lat_rad) + h) * std::cos(p.lat_rad);
        EXPECT_NEAR(std::remainder(q.lon_rad - p.lon_rad, 2 * M_PI) * east_scale_m, 0.0, 4e-9)
            << lat_deg << " " << lon_deg << " " << h;
        EXPECT_LT((LlhToEcef(q) - r).norm(), 4e-9) << lat_deg << " " << lon_deg << " " << h;
      }
    }
  }
}

TEST(EarthTest, EcefOfEquatorAndPoleAreTheSemiAxes) {
  // Definition of the ellipsoid: rounding only.
  EXPECT_LT((LlhToEcef({0.0, 0.0, 0.0}) - Vector3d(kWgs84SemiMajorAxis_m, 0, 0)).norm(), 1e-9);
  EXPECT_LT((LlhToEcef({M_PI / 2, 0.0, 0.0}) - Vector3d(0, 0, kWgs84SemiMinorAxis_m)).norm(), 1e-8);
  EXPECT_LT(
      (LlhToEcef({0.0, M_PI / 2, 100.0}) - Vector3d(0, kWgs84SemiMajorAxis_m + 100, 0)).norm(),
      1e-8);
}

TEST(EarthTest, NedRoundTripAndSmallDisplacementsFollowTheRadii) {
  const Llh ref{48.1374 * kDeg, 11.5755 * kDeg, 520.0};
  for (const Vector3d& r_n :
       {Vector3d(1000.0, -2000.0, 30.0), Vector3d(-5e4, 7e4, -1e3), Vector3d(0.1, 0.2, -0.3)}) {
    const Llh p = NedToLlh(r_n, ref);
    // Round trip through ECEF: rounding of 6.4e6 m coordinates, ~1e-9 m.
    EXPECT_LT((LlhToNed(p, ref) - r_n).norm(), 1e-8);
  }
  // A small step d north / east moves latitude by d / (R_N + h) and longitude by
  // d / ((R_E + h) cos L); the curvature term is d^2 / (2 R) ~ 8e-8 m for d = 1 m.
  const double d = 1.0;
  const Llh north{ref.lat_rad + d / (MeridianRadius(ref.lat_rad) + ref.h_m), ref.lon_rad, ref.h_m};
  const Llh east{
      ref.lat_rad,
      ref.lon_rad + d / ((TransverseRadius(ref.lat_rad) + ref.h_m) * std::cos(ref.lat_rad)),
      ref.h_m};
  EXPECT_LT((LlhToNed(north, ref) - Vector3d(d, 0, 0)).norm(), 1e-6);
  EXPECT_LT((LlhToNed(east, ref) - Vector3d(0, d, 0)).norm(), 1e-6);
  // The environment's metre scaling agrees with the exact conversion to first order.
  const NavEnvironment env = NavEnvironment::Wgs84();
  EXPECT_LT((env.PositionErrorNed(north, ref) - Vector3d(d, 0, 0)).norm(), 1e-6);
}

// The east error takes the longitude difference modulo 2 pi (nav_error_lanes.h: std::remainder,
// skipped where it would return its argument, |d lambda| <= pi): bit for bit the remainder formula
// over differences from -20 to 20 rad and at +-pi, and across the antimeridian the short way
// round. Tolerances: none for the bits; the metres across the antimeridian to 1e-8 m: the two
// longitudes are doubles near pi (rounded by up to 2.2e-16 rad each) and the period is 2 M_PI
// (2.4e-16 below 2 pi), so the difference is 2e-7 rad to within ~7e-16 rad, 4e-9 m on this
// 6.1e6 m radius.
TEST(EarthTest, PositionErrorTakesTheLongitudeDifferenceModuloTwoPi) {
  const NavEnvironment env = NavEnvironment::Wgs84();
  const Llh truth{0.3, 0.0, 100.0};
  const NavEnvironment::PositionScale scale = env.PositionScaleAt(truth);
  std::vector<double> dlambda = {
      M_PI, -M_PI, std::nextafter(M_PI, 4.0), std::nextafter(-M_PI, -4.0), 0.0, -0.0};
  for (int i = -2000; i <= 2000; ++i) dlambda.push_back(0.01 * i + 1e-3);
  for (const double d : dlambda) {
    const Llh estimate{truth.lat_rad, d, truth.h_m};
    const double expected = std::remainder(d, 2.0 * M_PI) * scale.east_m * scale.cos_L;
    const double east = env.PositionErrorNed(estimate, truth, scale).y();
    EXPECT_EQ(std::bit_cast<uint64_t>(east), std::bit_cast<uint64_t>(expected)) << "dlambda " << d;
  }
  const Llh west_of{truth.lat_rad, M_PI - 1e-7, truth.h_m};
  const Llh east_of{truth.lat_rad, -M_PI + 1e-7, truth.h_m};
  EXPECT_NEAR(env.PositionErrorNed(east_of, west_of).y(),
              2e-7 * (TransverseRadius(truth.lat_rad) + truth.h_m) * std::cos(truth.lat_rad), 1e-8);
}

TEST(EarthTest, LatitudeNearMatchesLongDoubleSinCosOnBothItsPaths) {
  // Latitude::Near rotates a known latitude's sin/cos by d = L - L0 with the Taylor series of
  // sin d, cos d (truncation < 3e-24 for |d| <= 0.01) and takes a full sin/cos beyond. Error:
  // the known sin/cos within 3e-16 (PolynomialMathTest), times |cos d| + |sin d| <= 1.42, plus
  // two roundings of ~1.1e-16 each: 8e-16 absolute. At d = 0.5 or 3 the series alone would be
  // off by > 1e-9, so these points show that the full sin/cos is taken there.
  double max_error = 0.0;
  for (int i = -30; i <= 30; ++i) {
    const double L0 = 1.55 * i / 30.0;
    const NavEnvironment::Latitude known = NavEnvironment::Latitude::Of(L0);
    for (double d : {0.0, 1e-12, -3e-9, 5e-7, -2e-5, 1e-3, -0.0099, 0.0101, -0.5, 3.0}) {
      const NavEnvironment::Latitude near = NavEnvironment::Latitude::Near(known, L0 + d);
      const long double L = static_cast<long double>(L0 + d);
      EXPECT_EQ(near.L_rad, L0 + d);
      max_error = std::max(max_error, std::fabs(near.sin_L - static_cast<double>(std::sin(L))));
      max_error = std::max(max_error, std::fabs(near.cos_L - static_cast<double>(std::cos(L))));
    }
  }
  EXPECT_LT(max_error, 8e-16);
}

TEST(EarthTest, EarthAndTransportRatesFollowGroves) {
  // omega_ie_n = Omega [cos L, 0, -sin L]; magnitude exactly Omega (rounding).
  for (double L = -1.5; L <= 1.5; L += 0.25) {
    EXPECT_NEAR(EarthRateNed(L).norm(), kWgs84EarthRate_rad_per_s, 1e-19);
    EXPECT_NEAR(EarthRateNed(L).z(), -kWgs84EarthRate_rad_per_s * std::sin(L), 1e-19);
  }
  // Eastward motion along the equator at V: the NED frame turns about north at V / (R_E + h).
  const Vector3d w = TransportRateNed(0.0, 0.0, Vector3d(0.0, 100.0, 0.0));
  EXPECT_NEAR(w.x(), 100.0 / kWgs84SemiMajorAxis_m, 1e-20);
  EXPECT_NEAR(w.z(), 0.0, 1e-20);
  // Flat frame: no rotation, constant gravity.
  const NavEnvironment flat = NavEnvironment::Flat({0.7, 0.1, 600.0}, 9.8);
  EXPECT_EQ(flat.EarthRate(0.7), Vector3d::Zero());
  EXPECT_EQ(flat.TransportRate(0.7, 0.0, Vector3d(1, 2, 3)), Vector3d::Zero());
  EXPECT_EQ(flat.Gravity(0.3, 1e4), Vector3d(0, 0, 9.8));
}

}  // namespace
}  // namespace driftlab
