// IMU catalogue, part 1 (presets.h): the instrument-grade presets of seed 001 and the IMUs of seeds
// 000, 002 and 003. Every number is copied from the source named in the preset's description or
// listed there under "assumed" with the reason.
#include <string>
#include <vector>

#include "sensors/presets_common.h"

namespace driftlab::presets {
namespace {

// ---- Grade presets: seed 001, "Calidad y categorías de giróscopos / acelerómetros" ----------
// Reading of the gyro table (its PDF text is scrambled): columns rate grade | tactical |
// aviation | navigation; ARW [deg/sqrt(h)] > 0.5 | 0.5-0.05 | < 0.05 | < 0.001; bias instability
// [deg/h] > 10 | 1-10 | aviation < 0.1 or < 0.01 (the aviation cells "< 0.1", "< 0.01" come
// unlabelled) | < 0.01 (1 nmi/h); scale factor [%] 0.1-1 | 0.01-0.1 | aviation < 0.01 or < 0.001 |
// < 0.001. Aviation values below satisfy the stricter reading (BI < 0.01 deg/h, SF < 0.001 %),
// hence both. Accelerometer table: columns low/automotive | tactical | navigation (no aviation
// and no industrial column); noise 0.5-5 mg/sqrt(Hz) | 50-500 ug/sqrt(Hz) | < 10 ug/sqrt(Hz);
// bias instability 10-100 mg | 0.2-1 mg | 10-100 ug; scale factor > 1 % | 100-1000 ppm | < 100 ppm;
// range 2 g (stability control) or 50 g (airbag) | > 50 g | 2-50 g.

ImuErrorModel RateGrade() {
  return Preset(
      "rate-grade",
      "Rate (consumer) grade IMU. Source: seed 001 grade tables, gyro column 'rate grade' and "
      "accelerometer column 'baja/automovil'. Gyro: ARW 1 deg/sqrt(h) (table > 0.5), bias "
      "instability 30 deg/h (table > 10), scale factor 0.3 % (table 0.1-1 %), range 500 deg/s "
      "(table 50-1000). Accel: noise 1 mg/sqrt(Hz) (table 0.5-5 mg/sqrt(Hz)), bias instability "
      "30 mg (table 10-100 mg), scale factor 2 % (table > 1 %), range 16 g (table: 2 g stability "
      "systems, 50 g airbag). Assumed: turn-on bias sigma = bias instability (the table's single "
      "'drift' row); flicker over tau 1-1000 s; misalignment 3 mrad; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(1.0),
            .bias_instability = DegPerH(30.0),
            .turn_on_bias_sigma = DegPerH(30.0),
            .scale_factor_sigma = Percent(0.3),
            .misalignment_sigma_rad = Mrad(3.0),
            .range = DegPerS(500.0)},
      Triad{.white_noise_density = MilliGPerSqrtHz(1.0),
            .bias_instability = MilliG(30.0),
            .turn_on_bias_sigma = MilliG(30.0),
            .scale_factor_sigma = Percent(2.0),
            .misalignment_sigma_rad = Mrad(3.0),
            .range = Gee(16.0)});
}

ImuErrorModel IndustrialGrade() {
  return Preset(
      "industrial",
      "Industrial grade IMU. Source: seed 001 grade tables, which have no industrial column: this "
      "preset sits between the rate-grade/automotive and tactical columns. Gyro: ARW 0.5 "
      "deg/sqrt(h), bias instability 10 deg/h, scale factor 0.1 % (the bounds shared by the two "
      "rows), range 500 deg/s. Accel: noise 0.5 mg/sqrt(Hz) (shared bound 500 ug/sqrt(Hz)), bias "
      "instability 3 mg (gap between 1 and 10 mg), scale factor 0.3 % (gap between 0.1 % and 1 %), "
      "range 16 g. Assumed: turn-on bias sigma = bias instability; flicker over tau 1-1000 s; "
      "misalignment 1 mrad; ranges 500 deg/s and 16 g; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.5),
            .bias_instability = DegPerH(10.0),
            .turn_on_bias_sigma = DegPerH(10.0),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = DegPerS(500.0)},
      Triad{.white_noise_density = MilliGPerSqrtHz(0.5),
            .bias_instability = MilliG(3.0),
            .turn_on_bias_sigma = MilliG(3.0),
            .scale_factor_sigma = Percent(0.3),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = Gee(16.0)});
}

ImuErrorModel TacticalGrade() {
  return Preset(
      "tactical",
      "Tactical grade IMU. Source: seed 001 grade tables, column 'tactico'; values near the "
      "geometric middle of each row. Gyro: ARW 0.15 deg/sqrt(h) (table 0.05-0.5), bias "
      "instability 3 deg/h (table 1-10), scale factor 0.03 % = 300 ppm (table 0.01-0.1 %), range "
      "1000 deg/s (table > 500). Accel: noise 150 ug/sqrt(Hz) (table 50-500), bias instability "
      "0.5 mg (table 0.2-1 mg), scale factor 300 ppm (table 100-1000 ppm), range 70 g (table > 50 "
      "g). Assumed: turn-on bias sigma = bias instability; flicker over tau 1-1000 s; "
      "misalignment 0.5 mrad; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.15),
            .bias_instability = DegPerH(3.0),
            .turn_on_bias_sigma = DegPerH(3.0),
            .scale_factor_sigma = Ppm(300.0),
            .misalignment_sigma_rad = Mrad(0.5),
            .range = DegPerS(1000.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(150.0),
            .bias_instability = MilliG(0.5),
            .turn_on_bias_sigma = MilliG(0.5),
            .scale_factor_sigma = Ppm(300.0),
            .misalignment_sigma_rad = Mrad(0.5),
            .range = Gee(70.0)});
}

ImuErrorModel AviationGrade() {
  return Preset(
      "aviation",
      "Aviation grade IMU (RLG/FOG). Source: seed 001 grade tables, gyro column 'aviacion'. Gyro: "
      "ARW 0.01 deg/sqrt(h) (table < 0.05), bias instability 0.008 deg/h (table < 0.1 or < 0.01: "
      "the scrambled table text allows both readings; the value satisfies the stricter), scale "
      "factor 8 ppm = 0.0008 % (table < 0.01 % or < 0.001 %). The accelerometer table has no "
      "aviation column; aviation INS pair these gyros with navigation-column accelerometers, so "
      "accel values lie inside the navigation row at its worse end: noise 8 ug/sqrt(Hz) (table < "
      "10), bias instability 50 ug (table 10-100 ug), scale factor 80 ppm (table < 100 ppm). "
      "Assumed: turn-on bias sigma = bias instability; flicker over tau 10-10000 s (Allan minimum "
      "of optical gyros lies at hundreds of seconds); misalignment 0.1 mrad; ranges 400 deg/s and "
      "25 g; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.01),
            .bias_instability = DegPerH(0.008),
            .tau_min_s = 10.0,
            .tau_max_s = 10000.0,
            .turn_on_bias_sigma = DegPerH(0.008),
            .scale_factor_sigma = Ppm(8.0),
            .misalignment_sigma_rad = Mrad(0.1),
            .range = DegPerS(400.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(8.0),
            .bias_instability = MicroG(50.0),
            .tau_min_s = 10.0,
            .tau_max_s = 10000.0,
            .turn_on_bias_sigma = MicroG(50.0),
            .scale_factor_sigma = Ppm(80.0),
            .misalignment_sigma_rad = Mrad(0.1),
            .range = Gee(25.0)});
}

ImuErrorModel NavigationGrade() {
  return Preset(
      "navigation",
      "Navigation grade IMU (hours of unaided navigation). Source: seed 001 grade tables, column "
      "'navegacion'. Gyro: ARW 0.0005 deg/sqrt(h) (table < 0.001), bias instability 0.003 deg/h "
      "(table < 0.01, about 1 nmi/h), scale factor 5 ppm = 0.0005 % (table < 0.001 %), range 500 "
      "deg/s (table > 400). Accel: noise 5 ug/sqrt(Hz) (table < 10), bias instability 15 ug "
      "(table 10-100 ug), scale factor 30 ppm (table < 100 ppm), range 25 g (table 2-50 g). "
      "Assumed: turn-on bias sigma = bias instability; flicker over tau 10-10000 s; misalignment "
      "0.05 mrad; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.0005),
            .bias_instability = DegPerH(0.003),
            .tau_min_s = 10.0,
            .tau_max_s = 10000.0,
            .turn_on_bias_sigma = DegPerH(0.003),
            .scale_factor_sigma = Ppm(5.0),
            .misalignment_sigma_rad = Mrad(0.05),
            .range = DegPerS(500.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(5.0),
            .bias_instability = MicroG(15.0),
            .tau_min_s = 10.0,
            .tau_max_s = 10000.0,
            .turn_on_bias_sigma = MicroG(15.0),
            .scale_factor_sigma = Ppm(30.0),
            .misalignment_sigma_rad = Mrad(0.05),
            .range = Gee(25.0)});
}

// ---- Seed 002: IMU catalogue of the inertial data generator --------------------------------
// Seed 002's model: f^b = (I - S_a) C f^n + eta, omega = (I - S_g)(...) + eps, with eta, eps =
// constant bias + white noise. Its catalogue gives bias and scale factor only; the datasheet
// bias is modelled as a 1-sigma turn-on bias and the scale factor as a 1-sigma random scale
// factor, and (as in seed 002) there is no bias instability. White noise is not given: it is
// taken from the seed 001 grade row in which the unit's bias falls.

ImuErrorModel Seed002CrossbowDmu() {
  return Preset(
      "seed002-crossbow-dmu",
      "Crossbow DMU. Source: seed 002 catalogue: accel bias 24 mg, gyro bias 20 deg/h, scale "
      "factor accel 1 %, gyro 1.5 %. Bias -> turn-on bias (1 sigma), scale factor -> scale-factor "
      "sigma. Assumed: white noise from the seed 001 row of its biases (gyro 20 deg/h > 10: rate "
      "grade, ARW 1 deg/sqrt(h); accel 24 mg in 10-100 mg: automotive, 1 mg/sqrt(Hz)); no bias "
      "instability, misalignment or saturation (seed 002's model has none).",
      Triad{.white_noise_density = DegPerSqrtH(1.0),
            .turn_on_bias_sigma = DegPerH(20.0),
            .scale_factor_sigma = Percent(1.5)},
      Triad{.white_noise_density = MilliGPerSqrtHz(1.0),
            .turn_on_bias_sigma = MilliG(24.0),
            .scale_factor_sigma = Percent(1.0)});
}

ImuErrorModel Seed002Epson() {
  return Preset(
      "seed002-epson",
      "Epson IMU of seed 002. Source: seed 002 catalogue: accel bias 8 mg, gyro bias 0.5 deg/s, "
      "scale factor 0 % for both. Bias -> turn-on bias (1 sigma). Assumed: white noise from the "
      "seed 001 row of its biases (gyro 0.5 deg/s = 1800 deg/h: rate grade, ARW 1 deg/sqrt(h); "
      "accel 8 mg between the tactical and automotive rows: industrial, 0.5 mg/sqrt(Hz)); no bias "
      "instability, misalignment or saturation.",
      Triad{.white_noise_density = DegPerSqrtH(1.0), .turn_on_bias_sigma = DegPerS(0.5)},
      Triad{.white_noise_density = MilliGPerSqrtHz(0.5), .turn_on_bias_sigma = MilliG(8.0)});
}

ImuErrorModel Seed002GladiatorLandmark() {
  return Preset(
      "seed002-gladiator-landmark",
      "Gladiator Technologies Landmark. Source: seed 002 catalogue: accel bias 0.1 mg, gyro bias "
      "25 deg/h, scale factor accel 0.2 %, gyro 0.2 %. Bias -> turn-on bias (1 sigma), scale "
      "factor -> scale-factor sigma. Assumed: white noise (gyro 25 deg/h > 10: rate grade, ARW 1 "
      "deg/sqrt(h); accel 0.1 mg lies between the seed 001 navigation (<= 100 ug) and tactical (>= "
      "0.2 mg) rows: the tactical noise 150 ug/sqrt(Hz) is used as the conservative choice for a "
      "low-cost MEMS unit); no bias instability, misalignment or saturation.",
      Triad{.white_noise_density = DegPerSqrtH(1.0),
            .turn_on_bias_sigma = DegPerH(25.0),
            .scale_factor_sigma = Percent(0.2)},
      Triad{.white_noise_density = MicroGPerSqrtHz(150.0),
            .turn_on_bias_sigma = MilliG(0.1),
            .scale_factor_sigma = Percent(0.2)});
}

// ---- Seed 000: FOG IMU of the 1:40 ship model -----------------------------------------------
ImuErrorModel Seed000FogImu() {
  return Preset(
      "seed000-fog-imu",
      "Strapdown IMU of the 1:40 ship model. Source: seed 000: fibre-optic gyros range +-200 "
      "deg/s, bias < +-0.03 deg/s; capacitive accelerometers range +-2 g, bias < +-8 mg. The bias "
      "bounds are modelled as 1-sigma turn-on biases (not bound / 3): the seed's 90 s static "
      "period measured gyro biases of 0.023, 0.027, 0.014 deg/s, i.e. 0.5-0.9 of the bound on "
      "every axis, which a sigma = bound / 3 model would make improbable. Assumed: gyro ARW 0.1 "
      "deg/sqrt(h) (small open-loop FOG; seed gives none), accel noise 100 ug/sqrt(Hz) "
      "(capacitive +-2 g accelerometer, tactical row of seed 001); no bias instability; scale "
      "factor 0.1 % and misalignment 1 mrad (not given).",
      Triad{.white_noise_density = DegPerSqrtH(0.1),
            .turn_on_bias_sigma = DegPerS(0.03),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = DegPerS(200.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(100.0),
            .turn_on_bias_sigma = MilliG(8.0),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = Gee(2.0)});
}

// ---- Seed 003: ADXRS300 gyros + ADXL330 accelerometer of the pico-satellite IMU --------------
// Gyro turn-on bias from the seed's characterisation: null at rest 2.47 / 2.45 / 2.45 V with a
// run-to-run spread of +-0.005 V (10 runs of 10 min), sensitivity from the 33 rpm = 198 deg/s
// turntable: x (3.52 - 1.51), y (3.39 - 1.36), z (3.37 - 1.38) V over 2 x 198 deg/s, mean
// 6.03 / 3 / 396 V/(deg/s) = 5.076 mV/(deg/s). sigma_b = 0.005 V / 5.076 mV/(deg/s) = 0.985 deg/s.
// Scale factor after the seed's two-point calibration: each end point has sigma 0.005 V, so the
// slope's relative sigma is sqrt(2) 0.005 V / 2.01 V (mean swing) = 0.35 %.
constexpr double kSeed003NullSpread_V = 0.005;
constexpr double kSeed003MeanSwing_V = (2.01 + 2.03 + 1.99) / 3.0;
constexpr double kSeed003Sensitivity_V_per_deg_s = kSeed003MeanSwing_V / (2.0 * 198.0);

ImuErrorModel Seed003AdxrsAdxl() {
  return Preset(
      "seed003-adxrs300-adxl330",
      "Pico-satellite IMU of seed 003: ADXRS300 gyros (+-300 deg/s; ADXRS300 datasheet Rev. B) "
      "and ADXL330 accelerometer (+-3 g; ADXL330 datasheet Rev. A). Gyro turn-on bias 0.985 "
      "deg/s (1 sigma) derived from seed 003's null spread +-0.005 V and its turntable "
      "sensitivity 5.076 mV/(deg/s); gyro scale factor 0.35 % from the same spread over the 2.01 V "
      "calibration swing. Assumed: rate noise density 0.1 (deg/s)/sqrt(Hz) and accel noise "
      "280 ug/sqrt(Hz) (x, y; z is 350) - the values given in the project brief for these "
      "datasheets, not found in the retrieved datasheet text; the model has one density per "
      "triad, so x/y's is used. Accel turn-on bias 10 mg and scale factor 1 % after the seed's "
      "linear calibration (seed gives no spread for the accelerometer); misalignment 5 mrad "
      "(three single-axis gyros hand-mounted); no bias instability.",
      Triad{.white_noise_density = DegPerSPerSqrtHz(0.1),
            .turn_on_bias_sigma = DegPerS(kSeed003NullSpread_V / kSeed003Sensitivity_V_per_deg_s),
            .scale_factor_sigma = 1.4142135623730951 * kSeed003NullSpread_V / kSeed003MeanSwing_V,
            .misalignment_sigma_rad = Mrad(5.0),
            .range = DegPerS(300.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(280.0),
            .turn_on_bias_sigma = MilliG(10.0),
            .scale_factor_sigma = Percent(1.0),
            .misalignment_sigma_rad = Mrad(5.0),
            .range = Gee(3.0)});
}

}  // namespace

std::vector<ImuErrorModel> GradeAndSeedPresets() {
  return {RateGrade(),          IndustrialGrade(), TacticalGrade(),
          AviationGrade(),      NavigationGrade(), Seed000FogImu(),
          Seed002CrossbowDmu(), Seed002Epson(),    Seed002GladiatorLandmark(),
          Seed003AdxrsAdxl()};
}

}  // namespace driftlab::presets
