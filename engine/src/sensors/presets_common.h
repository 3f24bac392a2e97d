// Shared by the catalogue's files (presets.cc, presets_grades.cc, presets_datasheets.cc): the
// datasheet-unit -> SI helpers every preset is written with, and the one-triad description a
// preset is built from. Datasheet units are converted by these constexpr helpers so that a
// preset's numbers read as in its source.
#pragma once

#include <charconv>
#include <numbers>
#include <string>
#include <vector>

#include "driftlab/earth.h"
#include "driftlab/sensor_params.h"

namespace driftlab::presets {
inline constexpr double kPi = std::numbers::pi;
inline constexpr double kG_m_per_s2 = kStandardGravity_m_per_s2;  // 1 g = 9.80665 m/s^2 (CGPM 1901)

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
// Specific force: 1 g = 9.80665 m/s^2; 1 mg = 1e-3 g; 1 ug = 1e-6 g.
constexpr double Gee(double g) { return g * kG_m_per_s2; }
constexpr double MilliG(double mg) { return mg * 1e-3 * kG_m_per_s2; }
constexpr double MicroG(double ug) { return ug * 1e-6 * kG_m_per_s2; }
// Accelerometer noise density: 1 ug/sqrt(Hz) = 1e-6 g (m/s^2)/sqrt(Hz) = 1e-6 g m/s/sqrt(s).
constexpr double MicroGPerSqrtHz(double v) { return MicroG(v); }
constexpr double MilliGPerSqrtHz(double v) { return MilliG(v); }
// Velocity random walk: 1 m/s/sqrt(h) = 1 m/s / sqrt(3600 s) = 1/60 m/s/sqrt(s) = (m/s^2)/sqrt(Hz).
constexpr double MPerSPerSqrtH(double v) { return v / 60.0; }
// Velocity random walk: 1 ft/s/sqrt(h) = 0.3048 / 60 m/s/sqrt(s) (international foot, exact).
constexpr double FtPerSPerSqrtH(double v) { return v * 0.3048 / 60.0; }
// Ratios: 1 ppm = 1e-6; 1 % = 1e-2.
constexpr double Ppm(double ppm) { return ppm * 1e-6; }
constexpr double Percent(double percent) { return percent * 1e-2; }
// Gyro g-sensitivity: 1 (deg/s)/g = (pi / 180) / 9.80665 (rad/s)/(m/s^2); likewise for (deg/h)/g.
constexpr double DegPerSPerG(double v) { return DegPerS(v) / kG_m_per_s2; }
constexpr double DegPerHPerG(double v) { return DegPerH(v) / kG_m_per_s2; }

// Shortest decimal text of a datasheet figure, for descriptions ("3.5", "0.0002").
inline std::string ShortestText(double x) {
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

inline TriadErrorParams ToParams(const Triad& t) {
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
inline ImuErrorModel Preset(std::string name, std::string description, const Triad& gyro,
                            const Triad& accel, double g_sensitivity = 0.0) {
  ImuErrorModel m;
  m.name = std::move(name);
  m.description = std::move(description);
  m.gyro = ToParams(gyro);
  m.accel = ToParams(accel);
  m.gyro_g_sensitivity = Eigen::Matrix3d::Identity() * g_sensitivity;
  return m;
}

// The catalogue's parts, each in catalogue order (presets.cc joins them).
// Seed 001's grade presets, then the IMUs of seeds 000, 002 and 003 (presets_grades.cc).
std::vector<ImuErrorModel> GradeAndSeedPresets();
// Current IMUs from public datasheets (presets_datasheets.cc).
std::vector<ImuErrorModel> DatasheetPresets();

}  // namespace driftlab::presets
