// IMU catalogue (presets.h): the catalogue in its fixed order, the lookup by name, and
// gnss-ins-sim's accuracy levels. The grade and seed presets are in presets_grades.cc, the
// datasheet presets in presets_datasheets.cc; every number there is copied from the source named
// in the preset's description or listed under "assumed" with the reason.
#include "driftlab/presets.h"

#include <string>
#include <vector>

#include "driftlab/spec_error.h"
#include "sensors/presets_common.h"

namespace driftlab {
namespace presets {
namespace {

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
      level + "_accuracy). Gyro: Gauss-Markov bias sigma " + ShortestText(gyro_drift_deg_per_h) +
      " deg/h, tau 100 s, starting at 0 in each run as gnss-ins-sim does (pathgen.bias_drift); "
      "ARW " +
      ShortestText(arw_deg_per_sqrt_h) +
      " deg/sqrt(h); constant bias 0. Accel: Gauss-Markov "
      "bias sigma " +
      ShortestText(accel_drift_m_per_s2) + " m/s^2, tau 100 s, starting at 0; VRW " +
      ShortestText(vrw_m_per_s_per_sqrt_h) +
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

}  // namespace
}  // namespace presets

namespace {

std::vector<ImuErrorModel> BuildCatalogue() {
  std::vector<ImuErrorModel> catalogue = presets::GradeAndSeedPresets();
  for (ImuErrorModel& m : presets::DatasheetPresets()) catalogue.push_back(std::move(m));
  for (ImuErrorModel m :
       {presets::GnssInsSimLow(), presets::GnssInsSimMid(), presets::GnssInsSimHigh()}) {
    catalogue.push_back(std::move(m));
  }
  return catalogue;
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