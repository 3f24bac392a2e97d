// Tests of the IMU catalogue (presets.h). Expected numbers come from the sources (seed tables,
// seed measurements, datasheet figures) converted by hand in this file, never from the code.
#include "driftlab/presets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <string>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.80665;  // standard gravity, CGPM 1901 (exact)
// Exact unit conversions differ from the catalogue's only by rounding in a few multiplications:
// relative error below 1e-15 per operation, so 1e-12 leaves a wide margin yet catches any wrong
// factor (the smallest plausible slip, e.g. g = 9.81 instead of 9.80665, is 3.5e-4).
constexpr double kRelTol = 1e-12;

void ExpectRelNear(double actual, double expected, const std::string& what) {
  EXPECT_NEAR(actual, expected, kRelTol * std::fabs(expected)) << what;
}

// Inverse conversions to datasheet units, written independently of presets.cc.
double ToDegPerSqrtH(double rad_per_sqrt_s) { return rad_per_sqrt_s * 180.0 / kPi * 60.0; }
double ToDegPerH(double rad_per_s) { return rad_per_s * 180.0 / kPi * 3600.0; }
double ToDegPerS(double rad_per_s) { return rad_per_s * 180.0 / kPi; }
double ToUgPerSqrtHz(double m_per_s2_per_sqrt_hz) { return m_per_s2_per_sqrt_hz / kG * 1e6; }
double ToMg(double m_per_s2) { return m_per_s2 / kG * 1e3; }
double ToPercent(double ratio) { return ratio * 100.0; }
double ToPpm(double ratio) { return ratio * 1e6; }

TEST(ImuCatalogue, EveryPresetPassesTheSensorModelValidation) {
  for (const ImuErrorModel& model : ImuCatalogue()) {
    EXPECT_NO_THROW(ValidateImuErrorModel(model, "sensor")) << model.name;
  }
}

TEST(ImuCatalogue, EveryPresetHasPositiveWhiteNoiseOnBothTriads) {
  for (const ImuErrorModel& model : ImuCatalogue()) {
    EXPECT_GT(model.gyro.white_noise_density, 0.0) << model.name;
    EXPECT_GT(model.accel.white_noise_density, 0.0) << model.name;
    EXPECT_GE(model.gyro.bias_flicker.bias_instability, 0.0) << model.name;
    EXPECT_GE(model.accel.bias_flicker.bias_instability, 0.0) << model.name;
  }
}

TEST(ImuCatalogue, EveryDescriptionCitesASourceAndStatesItsAssumptions) {
  for (const ImuErrorModel& model : ImuCatalogue()) {
    const std::string& d = model.description;
    const bool cites =
        d.find("seed 00") != std::string::npos || d.find("datasheet") != std::string::npos ||
        d.find("brochure") != std::string::npos || d.find("leaflet") != std::string::npos ||
        d.find("source code") != std::string::npos;  // another simulator's built-in models
    EXPECT_TRUE(cites) << model.name << ": " << d;
    // Every preset leaves something to assumption (no source gives every model term).
    EXPECT_NE(d.find("ssumed"), std::string::npos) << model.name;
  }
}

// Lowercase words of [a-z0-9] joined by single dashes: "a", "icm-42688-p"; not "A", "-a", "a--b".
bool IsLowercaseWithDashes(const std::string& name) {
  if (name.empty() || name.front() == '-' || name.back() == '-') return false;
  for (size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool word_char = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    if (c == '-') {
      if (name[i - 1] == '-') return false;
    } else if (!word_char) {
      return false;
    }
  }
  return true;
}

TEST(ImuCatalogue, NamesAreUniqueLowercaseWithDashes) {
  std::set<std::string> names;
  for (const ImuErrorModel& model : ImuCatalogue()) {
    EXPECT_TRUE(IsLowercaseWithDashes(model.name)) << model.name;
    EXPECT_TRUE(names.insert(model.name).second) << "duplicate " << model.name;
  }
  EXPECT_FALSE(IsLowercaseWithDashes("Tactical"));  // the checker itself rejects bad names
  EXPECT_FALSE(IsLowercaseWithDashes("a--b"));
  EXPECT_FALSE(IsLowercaseWithDashes("adis16470-"));
  // Brief: five grades, seed 000, seed 002 (3), seed 003 and at least eight datasheet IMUs.
  EXPECT_GE(names.size(), 18u);
}

TEST(ImuCatalogue, FindReturnsEveryPresetByName) {
  for (const ImuErrorModel& model : ImuCatalogue()) {
    EXPECT_EQ(&FindImuPreset(model.name), &model);
  }
}

TEST(ImuCatalogue, UnknownNameRaisesSpecErrorNamingFieldValueAndChoices) {
  try {
    FindImuPreset("tactical-grade-typo");
    FAIL() << "no exception";
  } catch (const SpecError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.field(), "sensor.preset");
    EXPECT_NE(message.find("sensor.preset"), std::string::npos) << message;
    EXPECT_NE(message.find("tactical-grade-typo"), std::string::npos) << message;
    EXPECT_NE(message.find("one of: "), std::string::npos) << message;
    for (const ImuErrorModel& model : ImuCatalogue()) {
      EXPECT_NE(message.find(model.name), std::string::npos) << model.name;
    }
  }
}

// Seed 001 grade tables (see presets.cc for the reading of the scrambled gyro table). Bounds in
// datasheet units; an open side is +-infinity. Aviation uses the stricter of the two readings.
struct Row {
  double lo, hi;
};
constexpr double kInf = std::numeric_limits<double>::infinity();
struct GyroRows {
  Row arw_deg_per_sqrt_h, bi_deg_per_h, sf_percent;
};
struct AccelRows {
  Row noise_ug_per_sqrt_hz, bi_mg, sf_ppm;
};

void ExpectIn(double value, Row row, const std::string& what) {
  EXPECT_GE(value, row.lo) << what;
  EXPECT_LE(value, row.hi) << what;
}

void ExpectGradeInTable(const std::string& name, const GyroRows& g, const AccelRows& a) {
  const ImuErrorModel& m = FindImuPreset(name);
  ExpectIn(ToDegPerSqrtH(m.gyro.white_noise_density), g.arw_deg_per_sqrt_h, name + " ARW");
  ExpectIn(ToDegPerH(m.gyro.bias_flicker.bias_instability), g.bi_deg_per_h, name + " gyro BI");
  ExpectIn(ToPercent(m.gyro.scale_factor_sigma), g.sf_percent, name + " gyro SF");
  ExpectIn(ToUgPerSqrtHz(m.accel.white_noise_density), a.noise_ug_per_sqrt_hz,
           name + " accel noise");
  ExpectIn(ToMg(m.accel.bias_flicker.bias_instability), a.bi_mg, name + " accel BI");
  ExpectIn(ToPpm(m.accel.scale_factor_sigma), a.sf_ppm, name + " accel SF");
}

TEST(GradePresets, RateGradeLiesInsideSeed001RateAndAutomotiveRows) {
  // Gyro: ARW > 0.5 deg/sqrt(h), BI > 10 deg/h, SF 0.1-1 %. Accel: noise 0.5-5 mg/sqrt(Hz),
  // BI 10-100 mg, SF > 1 % (= 10000 ppm).
  ExpectGradeInTable("rate-grade", {{0.5, kInf}, {10.0, kInf}, {0.1, 1.0}},
                     {{500.0, 5000.0}, {10.0, 100.0}, {10000.0, kInf}});
}

TEST(GradePresets, TacticalLiesInsideSeed001TacticalRows) {
  // Gyro: ARW 0.05-0.5, BI 1-10 deg/h, SF 0.01-0.1 %. Accel: 50-500 ug/sqrt(Hz), BI 0.2-1 mg,
  // SF 100-1000 ppm.
  ExpectGradeInTable("tactical", {{0.05, 0.5}, {1.0, 10.0}, {0.01, 0.1}},
                     {{50.0, 500.0}, {0.2, 1.0}, {100.0, 1000.0}});
}

TEST(GradePresets, AviationLiesInsideSeed001AviationGyroAndNavigationAccelRows) {
  // Gyro: ARW < 0.05, BI < 0.01 deg/h, SF < 0.001 % (stricter reading). Accel (no aviation
  // column): navigation row < 10 ug/sqrt(Hz), BI 10-100 ug, SF < 100 ppm.
  ExpectGradeInTable("aviation", {{0.0, 0.05}, {0.0, 0.01}, {0.0, 0.001}},
                     {{0.0, 10.0}, {0.010, 0.100}, {0.0, 100.0}});
}

TEST(GradePresets, NavigationLiesInsideSeed001NavigationRows) {
  // Gyro: ARW < 0.001, BI < 0.01 deg/h, SF < 0.001 %. Accel: < 10 ug/sqrt(Hz), 10-100 ug,
  // < 100 ppm.
  ExpectGradeInTable("navigation", {{0.0, 0.001}, {0.0, 0.01}, {0.0, 0.001}},
                     {{0.0, 10.0}, {0.010, 0.100}, {0.0, 100.0}});
}

TEST(GradePresets, IndustrialSitsBetweenSeed001RateAndTacticalRows) {
  // No industrial column: each value lies between the tactical row's upper bound and the
  // rate/automotive row's lower bound (inclusive; where they touch, on the shared bound).
  const double eps = 1e-9;  // relative slack for the values placed exactly on a shared bound
  ExpectGradeInTable("industrial",
                     {{0.5 * (1 - eps), 0.5 * (1 + eps)},
                      {10.0 * (1 - eps), 10.0 * (1 + eps)},
                      {0.1 * (1 - eps), 0.1 * (1 + eps)}},
                     {{500.0 * (1 - eps), 500.0 * (1 + eps)}, {1.0, 10.0}, {1000.0, 10000.0}});
}

TEST(GradePresets, GradesImproveMonotonicallyFromRateToNavigation) {
  const char* order[] = {"rate-grade", "industrial", "tactical", "aviation", "navigation"};
  for (int i = 0; i + 1 < 5; ++i) {
    const ImuErrorModel& worse = FindImuPreset(order[i]);
    const ImuErrorModel& better = FindImuPreset(order[i + 1]);
    EXPECT_GT(worse.gyro.white_noise_density, better.gyro.white_noise_density) << order[i];
    EXPECT_GT(worse.gyro.bias_flicker.bias_instability, better.gyro.bias_flicker.bias_instability)
        << order[i];
    EXPECT_GE(worse.accel.white_noise_density, better.accel.white_noise_density) << order[i];
    EXPECT_GT(worse.accel.bias_flicker.bias_instability, better.accel.bias_flicker.bias_instability)
        << order[i];
  }
}

TEST(UnitConversions, DatasheetFiguresConvertToSiByHand) {
  // 0.15 deg/sqrt(h) = 0.15 * pi/180 rad / sqrt(3600 s) = 0.15 * pi/180/60 rad/sqrt(s).
  ExpectRelNear(FindImuPreset("tactical").gyro.white_noise_density, 0.15 * kPi / 180.0 / 60.0,
                "tactical ARW");
  // 3 deg/h = 3 * pi/180 / 3600 rad/s.
  ExpectRelNear(FindImuPreset("tactical").gyro.bias_flicker.bias_instability,
                3.0 * kPi / 180.0 / 3600.0, "tactical gyro BI");
  // 150 ug/sqrt(Hz) = 150e-6 * 9.80665 (m/s^2)/sqrt(Hz).
  ExpectRelNear(FindImuPreset("tactical").accel.white_noise_density, 150e-6 * kG,
                "tactical accel noise");
  // 300 ppm = 3e-4.
  ExpectRelNear(FindImuPreset("tactical").accel.scale_factor_sigma, 3e-4, "tactical accel SF");
  // 0.34 deg/sqrt(h) = 0.34 pi/180/60 rad/sqrt(s) (ADIS16470 Rev. C Table 1 ARW).
  ExpectRelNear(FindImuPreset("adis16470").gyro.white_noise_density, 0.34 * kPi / 180.0 / 60.0,
                "ADIS16470 ARW");
  // 13 ug = 13e-6 * 9.80665 m/s^2.
  ExpectRelNear(FindImuPreset("adis16470").accel.bias_flicker.bias_instability, 13e-6 * kG,
                "ADIS16470 accel BI");
  // VRW 0.06 m/s/sqrt(h) = 0.06 / 60 m/s/sqrt(s) (revision 9); rev. 31: 0.024 m/s/sqrt(h).
  ExpectRelNear(FindImuPreset("stim300-rev9").accel.white_noise_density, 0.06 / 60.0,
                "STIM300 rev. 9 VRW");
  ExpectRelNear(FindImuPreset("stim300").accel.white_noise_density, 0.024 / 60.0,
                "STIM300 rev. 31 VRW");
  // 0.005 mg = 5e-6 * 9.80665 m/s^2; 0.3 deg/h = 0.3 pi/180/3600 rad/s (rev. 31).
  ExpectRelNear(FindImuPreset("stim300").accel.bias_flicker.bias_instability, 5e-6 * kG,
                "STIM300 rev. 31 accel BI");
  ExpectRelNear(FindImuPreset("stim300").gyro.bias_flicker.bias_instability,
                0.3 * kPi / 180.0 / 3600.0, "STIM300 rev. 31 gyro BI");
  // Epson M-G370PDG0: 24 uG, ARW 0.06 deg/sqrt(h), 0.01 deg misalignment, 360 deg/h initial bias.
  ExpectRelNear(FindImuPreset("epson-m-g370pdg0").accel.bias_flicker.bias_instability, 24e-6 * kG,
                "M-G370 accel BI");
  ExpectRelNear(FindImuPreset("epson-m-g370pdg0").gyro.white_noise_density,
                0.06 * kPi / 180.0 / 60.0, "M-G370 ARW");
  ExpectRelNear(FindImuPreset("epson-m-g370pdg0").gyro.misalignment_sigma_rad, 0.01 * kPi / 180.0,
                "M-G370 misalignment");
  ExpectRelNear(FindImuPreset("epson-m-g370pdg0").gyro.turn_on_bias_sigma,
                360.0 * kPi / 180.0 / 3600.0, "M-G370 initial bias");
  // ADIS16465-1: 3.6 ug accel BI; ADIS16505-1: 26.5 um/s^2 accel BI, 0.25 deg misalignment.
  ExpectRelNear(FindImuPreset("adis16465-1").accel.bias_flicker.bias_instability, 3.6e-6 * kG,
                "ADIS16465-1 accel BI");
  ExpectRelNear(FindImuPreset("adis16505-1").accel.bias_flicker.bias_instability, 26.5e-6,
                "ADIS16505-1 accel BI");
  ExpectRelNear(FindImuPreset("adis16505-1").gyro.misalignment_sigma_rad, 0.25 * kPi / 180.0,
                "ADIS16505-1 misalignment");
  // 1 (deg/h)/g = pi/180/3600 / 9.80665 (rad/s)/(m/s^2), on the diagonal.
  ExpectRelNear(FindImuPreset("stim300").gyro_g_sensitivity(1, 1), kPi / 180.0 / 3600.0 / kG,
                "STIM300 g-sensitivity");
  EXPECT_EQ(FindImuPreset("stim300").gyro_g_sensitivity(0, 1), 0.0);
  // VRW 0.065 ft/s/sqrt(h) = 0.065 * 0.3048 / 60 m/s/sqrt(s).
  ExpectRelNear(FindImuPreset("hg1700").accel.white_noise_density, 0.065 * 0.3048 / 60.0,
                "HG1700 VRW");
  // 0.003 (deg/s)/g = 0.003 pi/180 / 9.80665 (rad/s)/(m/s^2).
  ExpectRelNear(FindImuPreset("mti-300").gyro_g_sensitivity(2, 2), 0.003 * kPi / 180.0 / kG,
                "MTi-300 g-sensitivity");
  // +-0.05 deg misalignment = 0.05 pi/180 rad.
  ExpectRelNear(FindImuPreset("adis16495-1").gyro.misalignment_sigma_rad, 0.05 * kPi / 180.0,
                "ADIS16495 misalignment");
  // 2.8 mdps/sqrt(Hz) = 0.0028 pi/180 rad/sqrt(s).
  ExpectRelNear(FindImuPreset("icm-42688-p").gyro.white_noise_density, 0.0028 * kPi / 180.0,
                "ICM-42688-P gyro noise");
}

TEST(UnitConversions, CatalogueAgreesWithTheUnitsModule) {
  // The catalogue converts with its own constexpr helpers; the units module (units.h) parses the
  // same datasheet quantities independently. Both must give the same SI value.
  struct Case {
    double value_si;
    double value;
    const char* unit;
    Dimension dimension;
  };
  const Case cases[] = {
      {FindImuPreset("tactical").gyro.white_noise_density, 0.15, "deg/sqrt(h)",
       dims::kAngleRandomWalk},
      {FindImuPreset("navigation").gyro.bias_flicker.bias_instability, 0.003, "deg/h",
       dims::kAngularRate},
      {FindImuPreset("tactical").accel.white_noise_density, 150.0, "ug/sqrt(Hz)",
       dims::kVelocityRandomWalk},
      {FindImuPreset("seed002-crossbow-dmu").accel.turn_on_bias_sigma, 24.0, "mg",
       dims::kAcceleration},
      {FindImuPreset("stim300-rev9").accel.white_noise_density, 0.06, "m/s/sqrt(h)",
       dims::kVelocityRandomWalk},
      {FindImuPreset("hg1700").accel.white_noise_density, 0.065, "ft/s/sqrt(h)",
       dims::kVelocityRandomWalk},
      {FindImuPreset("adis16470").gyro.white_noise_density, 0.34, "deg/sqrt(h)",
       dims::kAngleRandomWalk},
      {FindImuPreset("icm-42688-p").gyro.white_noise_density, 0.0028, "(deg/s)/sqrt(Hz)",
       dims::kAngleRandomWalk},
      {FindImuPreset("stim300").gyro.scale_factor_sigma, 500.0, "ppm", dims::kDimensionless},
      {FindImuPreset("seed002-crossbow-dmu").gyro.scale_factor_sigma, 1.5, "%",
       dims::kDimensionless},
  };
  for (const Case& c : cases) {
    ExpectRelNear(c.value_si, ToSi(c.value, c.unit, c.dimension), c.unit);
  }
}

TEST(UnitConversions, AgreesWithSeed001RoundedEquivalences) {
  // Seed 001: 1 deg/h = 0.00028 deg/s (rounded to 2 significant digits: exact is 0.000277...,
  // so 1 % relative tolerance).
  const double bi_deg_per_s =
      ToDegPerS(FindImuPreset("rate-grade").gyro.bias_flicker.bias_instability);
  EXPECT_NEAR(bi_deg_per_s, 30.0 * 0.00028, 0.01 * 30.0 * 0.00028);
  // Seed 001: 1 (deg/s)/sqrt(Hz) = 60 deg/sqrt(h): seed 003's 0.1 (deg/s)/sqrt(Hz) is 6 deg/sqrt(h)
  // (exact equivalence, rounding tolerance only).
  ExpectRelNear(ToDegPerSqrtH(FindImuPreset("seed003-adxrs300-adxl330").gyro.white_noise_density),
                6.0, "ADXRS300 ARW");
}

TEST(SeedPresets, Seed002CatalogueMatchesTheThesis) {
  // Seed 002: Crossbow DMU accel bias 24 mg, gyro 20 deg/h; scale factor accel 1 %, gyro 1.5 %.
  const ImuErrorModel& crossbow = FindImuPreset("seed002-crossbow-dmu");
  ExpectRelNear(crossbow.accel.turn_on_bias_sigma, 24e-3 * kG, "Crossbow accel bias");
  ExpectRelNear(crossbow.gyro.turn_on_bias_sigma, 20.0 * kPi / 180.0 / 3600.0,
                "Crossbow gyro bias");
  ExpectRelNear(crossbow.accel.scale_factor_sigma, 0.01, "Crossbow accel SF");
  ExpectRelNear(crossbow.gyro.scale_factor_sigma, 0.015, "Crossbow gyro SF");
  // Epson: accel 8 mg, gyro 0.5 deg/s, scale factor 0 %.
  const ImuErrorModel& epson = FindImuPreset("seed002-epson");
  ExpectRelNear(epson.accel.turn_on_bias_sigma, 8e-3 * kG, "Epson accel bias");
  ExpectRelNear(epson.gyro.turn_on_bias_sigma, 0.5 * kPi / 180.0, "Epson gyro bias");
  EXPECT_EQ(epson.accel.scale_factor_sigma, 0.0);
  EXPECT_EQ(epson.gyro.scale_factor_sigma, 0.0);
  // Gladiator Landmark: accel 0.1 mg, gyro 25 deg/h, scale factor 0.2 % both.
  const ImuErrorModel& landmark = FindImuPreset("seed002-gladiator-landmark");
  ExpectRelNear(landmark.accel.turn_on_bias_sigma, 0.1e-3 * kG, "Landmark accel bias");
  ExpectRelNear(landmark.gyro.turn_on_bias_sigma, 25.0 * kPi / 180.0 / 3600.0,
                "Landmark gyro bias");
  ExpectRelNear(landmark.accel.scale_factor_sigma, 0.002, "Landmark accel SF");
  ExpectRelNear(landmark.gyro.scale_factor_sigma, 0.002, "Landmark gyro SF");
  // Seed 002's error model is constant bias + white noise only.
  for (const ImuErrorModel* m : {&crossbow, &epson, &landmark}) {
    EXPECT_EQ(m->gyro.bias_flicker.bias_instability, 0.0) << m->name;
    EXPECT_EQ(m->accel.bias_flicker.bias_instability, 0.0) << m->name;
  }
}

TEST(SeedPresets, Seed000FogImuExplainsTheStaticPeriodGyroBiases) {
  const ImuErrorModel& fog = FindImuPreset("seed000-fog-imu");
  ExpectRelNear(fog.gyro.range, 200.0 * kPi / 180.0, "FOG gyro range");
  ExpectRelNear(fog.accel.range, 2.0 * kG, "FOG accel range");
  // Seed 000, 90 s at rest: mean rates (-0.023, 0.027, 0.014) deg/s. Averaging 90 s of white
  // noise at the preset's ARW leaves sigma = N / sqrt(90 s), negligible here, so the means are
  // turn-on biases: each must lie within 3 sigma of the model (99.7 % per axis if Gaussian).
  const double measured_deg_per_s[] = {-0.023, 0.027, 0.014};
  const double sigma_deg_per_s = ToDegPerS(fog.gyro.turn_on_bias_sigma);
  const double averaged_noise_deg_per_s = ToDegPerS(fog.gyro.white_noise_density) / std::sqrt(90.0);
  EXPECT_LT(averaged_noise_deg_per_s, 0.1 * sigma_deg_per_s);
  double chi2 = 0.0;
  for (double b : measured_deg_per_s) {
    EXPECT_LT(std::fabs(b), 3.0 * sigma_deg_per_s) << b;
    chi2 += (b / sigma_deg_per_s) * (b / sigma_deg_per_s);
  }
  // Joint check: chi-square with 3 degrees of freedom, 99 % quantile 11.345 (and 1 % quantile
  // 0.115, so a sigma far larger than the data would also fail).
  EXPECT_LT(chi2, 11.345);
  EXPECT_GT(chi2, 0.115);
}

TEST(SeedPresets, Seed003GyroTurnOnBiasFollowsFromTheNullSpreadAndTurntableSensitivity) {
  const ImuErrorModel& m = FindImuPreset("seed003-adxrs300-adxl330");
  // Seed 003 turntable at 33 rpm = 33 * 360 / 60 = 198 deg/s: outputs x 1.51 / 3.52 V,
  // y 1.36 / 3.39 V, z 1.38 / 3.37 V; sensitivity = swing / (2 * 198 deg/s).
  const double sx = (3.52 - 1.51) / 396.0, sy = (3.39 - 1.36) / 396.0, sz = (3.37 - 1.38) / 396.0;
  const double sensitivity_V_per_deg_s = (sx + sy + sz) / 3.0;  // 5.076 mV/(deg/s)
  // Null repeatability +-0.005 V over 10 runs -> bias sigma = 0.005 V / sensitivity.
  ExpectRelNear(ToDegPerS(m.gyro.turn_on_bias_sigma), 0.005 / sensitivity_V_per_deg_s,
                "ADXRS300 turn-on bias");
  EXPECT_NEAR(ToDegPerS(m.gyro.turn_on_bias_sigma), 0.985, 0.0005);  // hand value, 3 digits
  ExpectRelNear(m.gyro.range, 300.0 * kPi / 180.0, "ADXRS300 range");
  ExpectRelNear(m.accel.range, 3.0 * kG, "ADXL330 range");
}

// ---- Bosch BMI088 ------------------------------------------------------------------------------
// Each figure below is the datasheet quantity as written (value + unit), converted by the units
// module (units.h ToSi) and compared with the catalogue at kRelTol (exact conversions, rounding
// only). Source (see the preset's description): BMI088 datasheet BST-BMI088-DS001 as quoted by
// driver notes citing it (noise 0.014 (deg/s)/sqrt(Hz), 160 ug/sqrt(Hz); offsets +-1 deg/s,
// +-20 mg; ranges +-2000 deg/s, +-24 g).
struct DatasheetFigure {
  const char* preset;
  double value_si;
  double value;
  const char* unit;
  Dimension dimension;
};

TEST(DatasheetPresets, Bmi088MatchesItsDatasheetFiguresThroughTheUnitsModule) {
  const ImuErrorModel& bmi = FindImuPreset("bmi088");
  const DatasheetFigure figures[] = {
      {"bmi088", bmi.gyro.white_noise_density, 0.014, "(deg/s)/sqrt(Hz)", dims::kAngleRandomWalk},
      {"bmi088", bmi.accel.white_noise_density, 160.0, "ug/sqrt(Hz)", dims::kVelocityRandomWalk},
      {"bmi088", bmi.gyro.turn_on_bias_sigma, 1.0, "deg/s", dims::kAngularRate},
      {"bmi088", bmi.accel.turn_on_bias_sigma, 20.0, "mg", dims::kAcceleration},
      {"bmi088", bmi.gyro.range, 2000.0, "deg/s", dims::kAngularRate},
      {"bmi088", bmi.accel.range, 24.0, "g", dims::kAcceleration},
  };
  for (const DatasheetFigure& f : figures) {
    ExpectRelNear(f.value_si, ToSi(f.value, f.unit, f.dimension),
                  std::string(f.preset) + " " + std::to_string(f.value) + " " + f.unit);
  }
}

TEST(DatasheetPresets, RateNoiseDensityRoundTripsToArwBySeed001Equivalence) {
  // Seed 001: 1 (deg/s)/sqrt(Hz) = 60 deg/sqrt(h), exactly. BMI088 0.014 -> 0.84 deg/sqrt(h).
  // Printed with 6 significant digits by the units module and parsed back, the value must survive
  // (relative rounding of the printed text < 5e-7).
  const double n_si = FindImuPreset("bmi088").gyro.white_noise_density;
  const std::string text = FormatQuantity(n_si, "deg/sqrt(h)", 6);
  EXPECT_EQ(text,
            FormatQuantity(ToSi(0.84, "deg/sqrt(h)", dims::kAngleRandomWalk), "deg/sqrt(h)", 6));
  const Quantity back = ParseQuantity(text, dims::kAngleRandomWalk, "arw");
  EXPECT_NEAR(back.value, 0.84, 5e-7 * 0.84);
  EXPECT_NEAR(back.value_si, n_si, 5e-7 * n_si);
}

TEST(DatasheetPresets, Bmi088ListsItsAssumptions) {
  const std::string& d = FindImuPreset("bmi088").description;
  EXPECT_NE(d.find("BST-BMI088-DS001"), std::string::npos);
  EXPECT_NE(d.find("Assumed"), std::string::npos);
}

// gnss-ins-sim's gnss_ins_sim/sim/imu_model.py (commit 966ff27) computes its parameters as
// b_drift [deg/h] * D2R / 3600, arw [deg/sqrt(h)] * D2R / 60, vrw [m/s/sqrt(h)] / 60 with
// D2R = pi / 180, b_corr = 100 s, b = 0; the presets must hold the same doubles (to 1 ulp: the
// operations are grouped differently) and start the Gauss-Markov bias at 0 as it does.
TEST(GnssInsSimPresets, HoldItsLowMidHighAccuracyParametersAndStartTheBiasAtZero) {
  struct Level {
    const char* name;
    double gyro_drift_deg_per_h, arw_deg_per_sqrt_h, accel_drift_m_per_s2, vrw_m_per_s_per_sqrt_h;
  };
  const double d2r = kPi / 180.0;
  for (const Level& l : {Level{"gnss-ins-sim-low", 10.0, 0.75, 2.0e-4, 0.05},
                         Level{"gnss-ins-sim-mid", 3.5, 0.25, 5.0e-5, 0.03},
                         Level{"gnss-ins-sim-high", 0.1, 2.0e-3, 3.6e-6, 2.5e-5}}) {
    SCOPED_TRACE(l.name);
    const ImuErrorModel& m = FindImuPreset(l.name);
    EXPECT_DOUBLE_EQ(m.gyro.bias_gauss_markov.sigma, l.gyro_drift_deg_per_h * d2r / 3600.0);
    EXPECT_DOUBLE_EQ(m.gyro.white_noise_density, l.arw_deg_per_sqrt_h * d2r / 60.0);
    EXPECT_DOUBLE_EQ(m.accel.bias_gauss_markov.sigma, l.accel_drift_m_per_s2);
    EXPECT_DOUBLE_EQ(m.accel.white_noise_density, l.vrw_m_per_s_per_sqrt_h / 60.0);
    for (const TriadErrorParams* t : {&m.gyro, &m.accel}) {
      EXPECT_EQ(t->bias_gauss_markov.tau_s, 100.0);
      EXPECT_TRUE(t->bias_gauss_markov.start_at_zero);
      EXPECT_EQ(t->fixed_bias, Eigen::Vector3d::Zero());
      EXPECT_EQ(t->turn_on_bias_sigma, 0.0);
      EXPECT_EQ(t->bias_flicker.bias_instability, 0.0);
      EXPECT_EQ(t->scale_factor_sigma, 0.0);
      EXPECT_EQ(t->misalignment_sigma_rad, 0.0);
    }
    EXPECT_NE(m.description.find("imu_model.py"), std::string::npos);
  }
}

}  // namespace
}  // namespace driftlab
