// IMU catalogue (presets.h). Every number below is either copied from the source named in the
// preset's description (seed document or datasheet) or listed there under "assumed" with the
// reason. Datasheet units are converted to SI by the constexpr helpers at the top of this file.
#include "driftlab/presets.h"

#include <charconv>
#include <numbers>
#include <string>

#include "driftlab/earth.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = kStandardGravity_m_per_s2;  // 1 g = 9.80665 m/s^2 (CGPM 1901)

// Angle: 1 deg = pi / 180 rad.
constexpr double Deg(double deg) { return deg * kPi / 180.0; }
// Angle: 1 mrad = 1e-3 rad.
constexpr double Mrad(double mrad) { return mrad * 1e-3; }
// Rate: 1 deg/s = pi / 180 rad/s.
constexpr double DegPerS(double deg_per_s) { return Deg(deg_per_s); }
// Rate: 1 deg/h = pi / 180 / 3600 rad/s (= 4.848e-6 rad/s; seed 001: 1 deg/h = 0.00028 deg/s).
constexpr double DegPerH(double deg_per_h) { return Deg(deg_per_h) / 3600.0; }
// Angle random walk: 1 deg/sqrt(h) = (pi / 180) rad / sqrt(3600 s) = pi / 180 / 60 rad/sqrt(s).
constexpr double DegPerSqrtH(double deg_per_sqrt_h) { return Deg(deg_per_sqrt_h) / 60.0; }
// Rate noise density: 1 (deg/s)/sqrt(Hz) = 1 deg/sqrt(s) = pi / 180 rad/sqrt(s) (seed 001).
constexpr double DegPerSPerSqrtHz(double v) { return Deg(v); }
// Specific force: 1 g = kG m/s^2; 1 mg = 1e-3 kG; 1 ug = 1e-6 kG.
constexpr double Gee(double g) { return g * kG; }
constexpr double MilliG(double mg) { return mg * 1e-3 * kG; }
constexpr double MicroG(double ug) { return ug * 1e-6 * kG; }
// Accelerometer noise density: 1 ug/sqrt(Hz) = 1e-6 kG (m/s^2)/sqrt(Hz) = 1e-6 kG m/s/sqrt(s).
constexpr double MicroGPerSqrtHz(double v) { return MicroG(v); }
constexpr double MilliGPerSqrtHz(double v) { return MilliG(v); }
// Velocity random walk: 1 m/s/sqrt(h) = 1 m/s / sqrt(3600 s) = 1/60 m/s/sqrt(s) = (m/s^2)/sqrt(Hz).
constexpr double MPerSPerSqrtH(double v) { return v / 60.0; }
// Velocity random walk: 1 ft/s/sqrt(h) = 0.3048 / 60 m/s/sqrt(s) (international foot, exact).
constexpr double FtPerSPerSqrtH(double v) { return v * 0.3048 / 60.0; }
// Ratios: 1 ppm = 1e-6; 1 % = 1e-2.
constexpr double Ppm(double ppm) { return ppm * 1e-6; }
constexpr double Percent(double percent) { return percent * 1e-2; }
// Gyro g-sensitivity: 1 (deg/s)/g = (pi / 180) / kG (rad/s)/(m/s^2); likewise for (deg/h)/g.
constexpr double DegPerSPerG(double v) { return DegPerS(v) / kG; }
constexpr double DegPerHPerG(double v) { return DegPerH(v) / kG; }

// Shortest decimal text of a datasheet figure, for descriptions ("3.5", "0.0002").
std::string Num(double x) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
  return std::string(buffer, result.ptr);
}

// One triad's parameters in the order the descriptions list them; converted to TriadErrorParams.
struct Triad {
  double white_noise_density = 0.0;  // [u/sqrt(Hz)]
  double bias_instability = 0.0;     // [u] flicker B; 0 = none
  double tau_min_s = 1.0;            // flicker averaging-time range [s]
  double tau_max_s = 1000.0;
  double turn_on_bias_sigma = 0.0;      // [u]
  double scale_factor_sigma = 0.0;      // [-]
  double misalignment_sigma_rad = 0.0;  // [rad]
  double range = 0.0;                   // [u]; 0 = no saturation
};

TriadErrorParams ToParams(const Triad& t) {
  TriadErrorParams p;
  p.white_noise_density = t.white_noise_density;
  p.bias_flicker.bias_instability = t.bias_instability;
  p.bias_flicker.tau_min_s = t.tau_min_s;
  p.bias_flicker.tau_max_s = t.tau_max_s;
  p.turn_on_bias_sigma = t.turn_on_bias_sigma;
  p.scale_factor_sigma = t.scale_factor_sigma;
  p.misalignment_sigma_rad = t.misalignment_sigma_rad;
  p.range = t.range;
  return p;
}

// g_sensitivity: same-axis gyro g-sensitivity [(rad/s)/(m/s^2)], placed on the diagonal.
ImuErrorModel Preset(std::string name, std::string description, const Triad& gyro,
                     const Triad& accel, double g_sensitivity = 0.0) {
  ImuErrorModel m;
  m.name = std::move(name);
  m.description = std::move(description);
  m.gyro = ToParams(gyro);
  m.accel = ToParams(accel);
  m.gyro_g_sensitivity = Eigen::Matrix3d::Identity() * g_sensitivity;
  return m;
}

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

// ---- Current IMUs from public datasheets ------------------------------------------------------
// "In-run bias stability" (Allan-deviation minimum) is taken as the flicker coefficient B, as
// sensor_params.h defines it; the Allan floor of the model is then 0.664 B. Datasheet bounds
// (+-x) are taken as 1 sigma.

ImuErrorModel Adis16470() {
  return Preset(
      "adis16470",
      "Analog Devices ADIS16470 (ADIS16470 datasheet Rev. C). Feature list (read in the Rev. C "
      "text): gyro range +-2000 deg/s, in-run bias stability 8 deg/h, rate noise density 0.008 "
      "(deg/s)/sqrt(Hz); accel range +-40 g, in-run bias stability 13 ug. Table 1 (as quoted "
      "from Rev. C's tables; the table itself was not retrievable here): gyro ARW 0.34 "
      "deg/sqrt(h), accel VRW 0.037 m/s/sqrt(h) (noise density 100 ug/sqrt(Hz) at 10-40 Hz), "
      "misalignment +-0.1 deg axis to axis (taken as 1 sigma). White noise is the Allan figure "
      "(ARW, VRW), which is what the model's white noise reproduces at tau = 1 s; the band-limited "
      "densities are 1.4x (gyro) and 1.6x (accel) larger. Assumed: turn-on bias 0.1 deg/s and 2 "
      "mg, scale factor 0.3 % (factory-calibrated MEMS IMU class; not in the retrieved text); "
      "flicker over tau 1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.34),
            .bias_instability = DegPerH(8.0),
            .turn_on_bias_sigma = DegPerS(0.1),
            .scale_factor_sigma = Percent(0.3),
            .misalignment_sigma_rad = Deg(0.1),
            .range = DegPerS(2000.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.037),
            .bias_instability = MicroG(13.0),
            .turn_on_bias_sigma = MilliG(2.0),
            .scale_factor_sigma = Percent(0.3),
            .misalignment_sigma_rad = Deg(0.1),
            .range = Gee(40.0)});
}

ImuErrorModel Adis16495() {
  return Preset(
      "adis16495-1",
      "Analog Devices ADIS16495-1 (ADIS16495 datasheet Rev. C). Datasheet: gyro range +-125 "
      "deg/s (-1 model), in-run bias stability 0.8 deg/h, ARW 0.09 deg/sqrt(h), axis-to-axis "
      "misalignment +-0.05 deg (taken as 1 sigma); accel range +-8 g, in-run bias stability 3.2 "
      "ug. Assumed: accel VRW 0.012 m/s/sqrt(h) (not in the retrieved text); turn-on bias 0.02 "
      "deg/s and 0.3 mg, scale factor 0.05 % (tactical MEMS class); accel misalignment = gyro's; "
      "flicker over tau 1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.09),
            .bias_instability = DegPerH(0.8),
            .turn_on_bias_sigma = DegPerS(0.02),
            .scale_factor_sigma = Percent(0.05),
            .misalignment_sigma_rad = Deg(0.05),
            .range = DegPerS(125.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.012),
            .bias_instability = MicroG(3.2),
            .turn_on_bias_sigma = MilliG(0.3),
            .scale_factor_sigma = Percent(0.05),
            .misalignment_sigma_rad = Deg(0.05),
            .range = Gee(8.0)});
}

ImuErrorModel Adis16467() {
  return Preset(
      "adis16467-1",
      "Analog Devices ADIS16467-1 (ADIS16467 datasheet Rev. C). Datasheet: gyro range +-125 "
      "deg/s (-1 model), in-run bias stability 2 deg/h, ARW 0.15 deg/sqrt(h), axis-to-axis "
      "misalignment +-0.05 deg (taken as 1 sigma); accel range +-40 g, in-run bias stability 13 "
      "ug. Assumed: accel noise density 230 ug/sqrt(Hz) (as adis16470, same +-40 g accelerometer "
      "class; not in the retrieved text); turn-on bias 0.05 deg/s and 2 mg, scale factor 0.3 %; "
      "flicker over tau 1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.15),
            .bias_instability = DegPerH(2.0),
            .turn_on_bias_sigma = DegPerS(0.05),
            .scale_factor_sigma = Percent(0.3),
            .misalignment_sigma_rad = Deg(0.05),
            .range = DegPerS(125.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(230.0),
            .bias_instability = MicroG(13.0),
            .turn_on_bias_sigma = MilliG(2.0),
            .scale_factor_sigma = Percent(0.3),
            .misalignment_sigma_rad = Deg(0.05),
            .range = Gee(40.0)});
}

ImuErrorModel Adis16465() {
  return Preset(
      "adis16465-1",
      "Analog Devices ADIS16465-1 (ADIS16465 datasheet, values read in its feature list). "
      "Datasheet: gyro range +-125 deg/s (-1 model), in-run bias stability 2 deg/h, ARW 0.15 "
      "deg/sqrt(h), axis-to-axis misalignment +-0.05 deg (taken as 1 sigma); accel range +-8 g, "
      "in-run bias stability 3.6 ug. Assumed: accel VRW 0.012 m/s/sqrt(h) (not in the feature "
      "list; as adis16495-1, the same +-8 g accelerometer class); turn-on bias 0.05 deg/s and "
      "0.3 mg, scale factor 0.1 % (factory-calibrated tactical MEMS class); accel misalignment = "
      "gyro's; flicker over tau 1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.15),
            .bias_instability = DegPerH(2.0),
            .turn_on_bias_sigma = DegPerS(0.05),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Deg(0.05),
            .range = DegPerS(125.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.012),
            .bias_instability = MicroG(3.6),
            .turn_on_bias_sigma = MilliG(0.3),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Deg(0.05),
            .range = Gee(8.0)});
}

ImuErrorModel Adis16505() {
  return Preset(
      "adis16505-1",
      "Analog Devices ADIS16505-1 (ADIS16505 datasheet, values as quoted from its feature list; "
      "the datasheet itself was not retrievable here). Datasheet: gyro range "
      "+-125 deg/s (-1 "
      "model), ARW 0.13 deg/sqrt(h), in-run bias stability 2.3 deg/h; accel in-run bias "
      "stability 26.5 um/s^2 (2.7 ug); misalignment 0.25 deg axis to axis (taken as 1 sigma). "
      "Assumed: accel range +-8 g and VRW 0.012 m/s/sqrt(h) (as adis16465-1, not in the quoted "
      "list); turn-on bias 0.05 deg/s and 0.3 mg, scale factor 0.1 %; accel misalignment = "
      "gyro's; flicker over tau 1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.13),
            .bias_instability = DegPerH(2.3),
            .turn_on_bias_sigma = DegPerS(0.05),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Deg(0.25),
            .range = DegPerS(125.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.012),
            .bias_instability = 26.5e-6,  // 26.5 um/s^2, the datasheet's own SI figure
            .turn_on_bias_sigma = MilliG(0.3),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Deg(0.25),
            .range = Gee(8.0)});
}

ImuErrorModel Icm42688p() {
  return Preset(
      "icm-42688-p",
      "TDK InvenSense ICM-42688-P (ICM-42688-P datasheet DS-000347 Rev. 1.7). Datasheet: gyro "
      "noise 2.8 mdps/sqrt(Hz), accel noise 70 ug/sqrt(Hz), full-scale ranges up to +-2000 deg/s "
      "and +-16 g (largest selected). Assumed (not in the retrieved text): gyro bias instability "
      "5 deg/h and accel bias instability 40 ug (consumer MEMS class), turn-on bias 0.5 deg/s and "
      "20 mg, scale factor 0.5 %, misalignment 2 mrad; flicker over tau 1-1000 s; no random "
      "walk; 16-bit output quantization not modelled (depends on the selected range).",
      Triad{.white_noise_density = DegPerSPerSqrtHz(0.0028),
            .bias_instability = DegPerH(5.0),
            .turn_on_bias_sigma = DegPerS(0.5),
            .scale_factor_sigma = Percent(0.5),
            .misalignment_sigma_rad = Mrad(2.0),
            .range = DegPerS(2000.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(70.0),
            .bias_instability = MicroG(40.0),
            .turn_on_bias_sigma = MilliG(20.0),
            .scale_factor_sigma = Percent(0.5),
            .misalignment_sigma_rad = Mrad(2.0),
            .range = Gee(16.0)});
}

ImuErrorModel MtI300() {
  return Preset(
      "mti-300",
      "Movella (Xsens) MTi-300 (MTi-300 product leaflet, Movella, May 2023). Datasheet: gyro "
      "standard full range 450 deg/s, in-run bias stability 10 deg/h, noise density 0.01 "
      "(deg/s)/sqrt(Hz), g-sensitivity (calibrated) 0.003 (deg/s)/g; accel standard full range "
      "20 g, in-run bias stability 15 ug, noise density 60 ug/sqrt(Hz). Assumed: g-sensitivity "
      "on the diagonal only (the leaflet gives one number); turn-on bias 0.2 deg/s and 5 mg, "
      "scale factor 0.1 %, misalignment 1 mrad (not in the leaflet); flicker over tau 1-1000 s; "
      "no random walk.",
      Triad{.white_noise_density = DegPerSPerSqrtHz(0.01),
            .bias_instability = DegPerH(10.0),
            .turn_on_bias_sigma = DegPerS(0.2),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = DegPerS(450.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(60.0),
            .bias_instability = MicroG(15.0),
            .turn_on_bias_sigma = MilliG(5.0),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = Gee(20.0)},
      DegPerSPerG(0.003));
}

ImuErrorModel Stim300Rev9() {
  return Preset(
      "stim300-rev9",
      "Safran Sensonor STIM300, 10 g accelerometer option (STIM300 datasheet revision 9, values "
      "as quoted by the NavToolkit stim300_model documentation, which links that revision; the "
      "datasheet itself was not retrieved). Gyro: bias instability 0.5 deg/h (Sensonor FAQ: "
      "minimum of the Allan curve), ARW 0.15 deg/sqrt(h), scale factor 500 ppm, misalignment 1 "
      "mrad, g-sensitivity 1 (deg/h)/g with g-compensation; range 400 deg/s. Accel: bias "
      "instability 0.05 mg, VRW 0.06 m/s/sqrt(h), scale factor 300 ppm, bias on/off repeatability "
      "0.75 mg, misalignment 1 mrad, range 10 g. Gyro turn-on repeatability 4 deg/h (1 sigma) as "
      "tabulated from the manufacturer in NAVIGATION (ION) journal's STIM300 noise table. "
      "Assumed: +-bounds taken as 1 sigma; g-sensitivity on the diagonal; flicker over tau "
      "1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.15),
            .bias_instability = DegPerH(0.5),
            .turn_on_bias_sigma = DegPerH(4.0),
            .scale_factor_sigma = Ppm(500.0),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = DegPerS(400.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.06),
            .bias_instability = MilliG(0.05),
            .turn_on_bias_sigma = MilliG(0.75),
            .scale_factor_sigma = Ppm(300.0),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = Gee(10.0)},
      DegPerHPerG(1.0));
}

// STIM300 datasheet TS1524 rev. 31 (figures as quoted from its tables 5-3 and 5-5; the revision
// itself was not retrievable here, revision 9's figures above come through NavToolkit). Bias
// instability is the minimum of the Allan curve (Sensonor FAQ: "lowest point of curve", 20 h test
// at 1000 Hz); the sheet also gives the Allan deviation at 600 s (0.5 deg/h gyro, 0.006 mg accel),
// which this model does not fit separately: with ARW 0.15 deg/sqrt(h) the white noise alone gives
// N / sqrt(tau) = 0.15 deg/sqrt(h) / sqrt(1/6 h) = 0.37 deg/h at 600 s, and the flicker floor
// 0.664 B = 0.20 deg/h, together 0.42 deg/h.
ImuErrorModel Stim300() {
  return Preset(
      "stim300",
      "Safran Sensonor STIM300, 10 g accelerometer option (STIM300 datasheet TS1524 rev. 31, "
      "values as quoted from its tables 5-3 and 5-5; that revision was not "
      "retrievable here). Gyro: bias instability 0.3 deg/h (minimum of the Allan curve; 0.5 deg/h "
      "at 600 s not modelled separately), ARW 0.15 deg/sqrt(h), scale-factor accuracy +-500 ppm, "
      "range 400 deg/s. Accel: bias instability 0.005 mg (0.006 mg at 600 s), VRW 0.024 "
      "m/s/sqrt(h), scale-factor accuracy +-200 ppm, range 10 g. From revision 9 (as stim300-rev9, "
      "not in the rev. 31 figures quoted): gyro turn-on repeatability 4 deg/h, g-sensitivity 1 "
      "(deg/h)/g with g-compensation, accel bias on/off repeatability 0.75 mg, misalignment 1 "
      "mrad. "
      "Assumed: +-bounds taken as 1 sigma; g-sensitivity on the diagonal; flicker over tau "
      "1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.15),
            .bias_instability = DegPerH(0.3),
            .turn_on_bias_sigma = DegPerH(4.0),
            .scale_factor_sigma = Ppm(500.0),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = DegPerS(400.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.024),
            .bias_instability = MilliG(0.005),
            .turn_on_bias_sigma = MilliG(0.75),
            .scale_factor_sigma = Ppm(200.0),
            .misalignment_sigma_rad = Mrad(1.0),
            .range = Gee(10.0)},
      DegPerHPerG(1.0));
}

// Epson M-G370PDG0 (figures as quoted from the full data sheet E Rev. 1.1, Table 1.3; the
// document was not retrievable here).
ImuErrorModel EpsonMG370() {
  return Preset(
      "epson-m-g370pdg0",
      "Epson M-G370PDG0 (M-G370PDG0 datasheet E Rev. 1.1, values as quoted from its Table 1.3; "
      "the document was not retrievable here). Gyro: range +-450 deg/s, bias "
      "instability 0.8 deg/h, ARW 0.06 deg/sqrt(h), initial bias 360 deg/h (1 sigma), scale factor "
      "+-0.2 %; accel: range +-16 G (largest selected), bias instability 24 uG, VRW 0.02 "
      "m/s/sqrt(h), initial bias 2 mG (1 sigma), scale factor +-0.1 %; misalignment 0.01 deg (1 "
      "sigma). Assumed: +-bounds taken as 1 sigma; flicker over tau 1-1000 s; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.06),
            .bias_instability = DegPerH(0.8),
            .turn_on_bias_sigma = DegPerH(360.0),
            .scale_factor_sigma = Percent(0.2),
            .misalignment_sigma_rad = Deg(0.01),
            .range = DegPerS(450.0)},
      Triad{.white_noise_density = MPerSPerSqrtH(0.02),
            .bias_instability = MicroG(24.0),
            .turn_on_bias_sigma = MilliG(2.0),
            .scale_factor_sigma = Percent(0.1),
            .misalignment_sigma_rad = Deg(0.01),
            .range = Gee(16.0)});
}

ImuErrorModel Hg1700() {
  return Preset(
      "hg1700",
      "Honeywell HG1700 (HG1700 brochure N61-1619-000-001, values as quoted, all 1 sigma, by the "
      "NavToolkit hg1700_model documentation; the brochure itself was not retrieved). Gyro bias 1 "
      "deg/h, ARW 0.125 deg/sqrt(h); accel bias 1 mg, VRW 0.065 ft/s/sqrt(h). Bias -> turn-on "
      "bias (1 sigma). Assumed: no separate in-run instability (the brochure figure is used as "
      "the run-to-run bias); scale factor 300 ppm for both (tactical row of seed 001); "
      "misalignment 0.5 mrad; ranges 1000 deg/s and 50 g; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.125),
            .turn_on_bias_sigma = DegPerH(1.0),
            .scale_factor_sigma = Ppm(300.0),
            .misalignment_sigma_rad = Mrad(0.5),
            .range = DegPerS(1000.0)},
      Triad{.white_noise_density = FtPerSPerSqrtH(0.065),
            .turn_on_bias_sigma = MilliG(1.0),
            .scale_factor_sigma = Ppm(300.0),
            .misalignment_sigma_rad = Mrad(0.5),
            .range = Gee(50.0)});
}

ImuErrorModel Hg9900() {
  return Preset(
      "hg9900",
      "Honeywell HG9900 (HG9900 brochure N61-1638-000-000, values as quoted, all 1 sigma, by the "
      "NavToolkit hg9900_model documentation; the brochure itself was not retrieved). Gyro bias "
      "0.0035 deg/h, ARW 0.002 deg/sqrt(h), scale factor 5 ppm; accel bias 25 ug, scale factor "
      "100 ppm. Bias -> turn-on bias (1 sigma). Assumed: accel VRW 5 ug/sqrt(Hz) (none listed; "
      "navigation row of seed 001, < 10 ug/sqrt(Hz)); no separate in-run instability; "
      "misalignment 0.05 mrad; ranges 400 deg/s and 25 g; no random walk.",
      Triad{.white_noise_density = DegPerSqrtH(0.002),
            .turn_on_bias_sigma = DegPerH(0.0035),
            .scale_factor_sigma = Ppm(5.0),
            .misalignment_sigma_rad = Mrad(0.05),
            .range = DegPerS(400.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(5.0),
            .turn_on_bias_sigma = MicroG(25.0),
            .scale_factor_sigma = Ppm(100.0),
            .misalignment_sigma_rad = Mrad(0.05),
            .range = Gee(25.0)});
}

// Bosch BMI088: the datasheet PDF itself was not retrievable; the description says which figures
// were read from a retrieved source quoting the datasheet ("quoted") and which are assumptions of
// the model class ("assumed"). (Honeywell HG4930 and Xsens MTi-630 are not in the catalogue: no
// retrievable source gives their figures, and a catalogue entry must cite one.)

ImuErrorModel Bmi088() {
  return Preset(
      "bmi088",
      "Bosch Sensortec BMI088 (BMI088 datasheet BST-BMI088-DS001, rev. 1.9, values as quoted by "
      "public driver notes and test scripts that cite it; the datasheet itself was not "
      "retrieved). Quoted: gyro rate noise density 0.014 (deg/s)/sqrt(Hz), zero-rate offset +-1 "
      "deg/s, range up to +-2000 deg/s; accel noise density 160 ug/sqrt(Hz) (x, y; z is 190), "
      "zero-g offset +-20 mg, range up to +-24 g (largest selected). Offsets -> turn-on bias (1 "
      "sigma). Assumed: gyro bias instability 2 deg/h (no retrieved source gives it); accel "
      "bias instability 40 ug (consumer MEMS class, as icm-42688-p); scale factor 0.5 % gyro and "
      "accel, "
      "misalignment 2 mrad (consumer MEMS class); one noise density per triad (x/y's); flicker "
      "over "
      "tau 1-1000 s; no random walk; 16-bit quantization not modelled.",
      Triad{.white_noise_density = DegPerSPerSqrtHz(0.014),
            .bias_instability = DegPerH(2.0),
            .turn_on_bias_sigma = DegPerS(1.0),
            .scale_factor_sigma = Percent(0.5),
            .misalignment_sigma_rad = Mrad(2.0),
            .range = DegPerS(2000.0)},
      Triad{.white_noise_density = MicroGPerSqrtHz(160.0),
            .bias_instability = MicroG(40.0),
            .turn_on_bias_sigma = MilliG(20.0),
            .scale_factor_sigma = Percent(0.5),
            .misalignment_sigma_rad = Mrad(2.0),
            .range = Gee(24.0)});
}

// ---- gnss-ins-sim's built-in accuracy levels
// ------------------------------------------------------ Source code: gnss_ins_sim/sim/imu_model.py
// of github.com/Aceinna/gnss-ins-sim, commit 966ff271bf21d08fbd0e31d1eb47fa5f3acef8d3, dictionaries
// gyro_/accel_{low,mid,high}_accuracy, in that tool's own parametrisation: 'b' constant bias (0 in
// all three), 'b_drift' the 1-sigma of a first-order Gauss-Markov bias with correlation time
// 'b_corr' (100 s in all three), 'arw' / 'vrw' white noise. pathgen.bias_drift() starts that bias
// at 0 in every run, hence start_at_zero. Its discretisation b_{k+1} = (1 - dt / tau) b_k + sigma
// sqrt(1 - exp(-2 dt / tau)) w_k differs from driftlab's exact a = exp(-dt / tau) by (dt / tau)^2 /
// 2 in a (5e-9 at 100 Hz): the bias variance at time t differs by less than 1e-4 relative. Its
// white noise, arw / sqrt(dt) per point sample, is driftlab's point-sample white noise of density
// arw.

ImuErrorModel GnssInsSimAccuracy(const char* level, double gyro_drift_deg_per_h,
                                 double arw_deg_per_sqrt_h, double accel_drift_m_per_s2,
                                 double vrw_m_per_s_per_sqrt_h) {
  const std::string name = std::string("gnss-ins-sim-") + level;
  const std::string description =
      std::string("gnss-ins-sim's built-in '") + level +
      "-accuracy' IMU (source code: gnss_ins_sim/sim/imu_model.py, github.com/Aceinna/"
      "gnss-ins-sim commit 966ff27, gyro_/accel_" +
      level + "_accuracy). Gyro: Gauss-Markov bias sigma " + Num(gyro_drift_deg_per_h) +
      " deg/h, tau 100 s, starting at 0 in each run as gnss-ins-sim does (pathgen.bias_drift); "
      "ARW " +
      Num(arw_deg_per_sqrt_h) +
      " deg/sqrt(h); constant bias 0. Accel: Gauss-Markov "
      "bias sigma " +
      Num(accel_drift_m_per_s2) + " m/s^2, tau 100 s, starting at 0; VRW " +
      Num(vrw_m_per_s_per_sqrt_h) +
      " m/s/sqrt(h); constant bias 0. Assumed: nothing else "
      "(gnss-ins-sim models no turn-on bias, scale factor, misalignment, random walk, "
      "quantization or range; all off here).";
  ImuErrorModel m;
  m.name = name;
  m.description = description;
  m.gyro.bias_gauss_markov = {DegPerH(gyro_drift_deg_per_h), 100.0, true};
  m.gyro.white_noise_density = DegPerSqrtH(arw_deg_per_sqrt_h);
  m.accel.bias_gauss_markov = {accel_drift_m_per_s2, 100.0, true};
  m.accel.white_noise_density = MPerSPerSqrtH(vrw_m_per_s_per_sqrt_h);
  return m;
}

ImuErrorModel GnssInsSimLow() { return GnssInsSimAccuracy("low", 10.0, 0.75, 2.0e-4, 0.05); }
ImuErrorModel GnssInsSimMid() { return GnssInsSimAccuracy("mid", 3.5, 0.25, 5.0e-5, 0.03); }
ImuErrorModel GnssInsSimHigh() { return GnssInsSimAccuracy("high", 0.1, 2.0e-3, 3.6e-6, 2.5e-5); }

std::vector<ImuErrorModel> BuildCatalogue() {
  return {RateGrade(),
          IndustrialGrade(),
          TacticalGrade(),
          AviationGrade(),
          NavigationGrade(),
          Seed000FogImu(),
          Seed002CrossbowDmu(),
          Seed002Epson(),
          Seed002GladiatorLandmark(),
          Seed003AdxrsAdxl(),
          Adis16470(),
          Adis16495(),
          Adis16467(),
          Adis16465(),
          Adis16505(),
          Icm42688p(),
          MtI300(),
          Stim300(),
          Stim300Rev9(),
          EpsonMG370(),
          Hg1700(),
          Hg9900(),
          Bmi088(),
          GnssInsSimLow(),
          GnssInsSimMid(),
          GnssInsSimHigh()};
}

}  // namespace

const std::vector<ImuErrorModel>& ImuCatalogue() {
  static const std::vector<ImuErrorModel> catalogue = BuildCatalogue();
  return catalogue;
}

const ImuErrorModel& FindImuPreset(std::string_view name) {
  const std::vector<ImuErrorModel>& catalogue = ImuCatalogue();
  for (const ImuErrorModel& model : catalogue) {
    if (model.name == name) return model;
  }
  std::string names;
  for (const ImuErrorModel& model : catalogue) {
    if (!names.empty()) names += ", ";
    names += model.name;
  }
  throw SpecError("sensor.preset", std::string(name), "one of: " + names);
}

}  // namespace driftlab
