// The odometer aid through the job schema: job.proto aiding.odometer -> ToMonteCarloSpec (the
// example's values and the defaults), every field's range refused with its path, and the aid's
// place among the EKF's aids (short scenarios; the statistical checks are in
// odometer_job_slow_test.cc).
#include <gtest/gtest.h>

#include <string>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

// 20 s at rest, then accelerating to 10 m/s and 30 s straight, 50 Hz, tactical IMU, 2 runs.
std::string OdometerJobJson(const std::string& filter, const std::string& aiding) {
  return R"({"name": "odometer", "rate_hz": 50,
    "motion": {"initial": {"lat_deg": 45, "lon_deg": 7, "height_m": 300, "yaw_deg": 30},
               "segments": [{"static": {"duration_s": 20}},
                            {"accelerate": {"acceleration_m_per_s2": 2, "target_speed_m_per_s": 10}},
                            {"constant_velocity": {"duration_s": 30}}]},
    "navigation": {"filter": ")" +
         filter + R"("}, "aiding": )" + aiding + R"(,
    "sensor": {"preset": "tactical"},
    "monte_carlo": {"runs": 2, "seed": 5, "initial_errors": {"position_ned_m": [1, 1, 1]}}})";
}

std::string OdometerJobError(const std::string& json) {
  try {
    const MonteCarloSpec spec = ToMonteCarloSpec(JobFile{ParseJobJson(json), "."}, {});
    RunMonteCarloWithAnalysis(spec);
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

TEST(OdometerJob, ExampleTranslatesToTheOdometerWithItsScaleFactorAndLeverArm) {
  const JobFile file =
      LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/car_drive_gnss_odometer.json");
  const MonteCarloSpec spec = ToMonteCarloSpec(file, {});
  ASSERT_TRUE(spec.aiding.odometer.has_value());
  const OdometerConfig& o = *spec.aiding.odometer;
  EXPECT_EQ(o.rate_hz, 10.0);
  EXPECT_EQ(o.speed_sigma_m_per_s, 0.05);
  EXPECT_EQ(o.scale_factor_sigma, 2000e-6);
  EXPECT_EQ(o.lever_arm_b_m, Eigen::Vector3d(0.0, 0.0, 0.3));
  EXPECT_TRUE(o.non_holonomic);
  EXPECT_EQ(o.non_holonomic_sigma_m_per_s, 0.1);
  EXPECT_TRUE(spec.aiding.gnss.has_value());
}

TEST(OdometerJob, DefaultsAndAnOdometerOnlyFilterRuns) {
  const MonteCarloSpec spec = ToMonteCarloSpec(
      JobFile{ParseJobJson(OdometerJobJson("INS_GNSS_EKF", R"({"odometer": {}})")), "."}, {});
  ASSERT_TRUE(spec.aiding.odometer.has_value());
  const OdometerConfig& o = *spec.aiding.odometer;
  EXPECT_EQ(o.rate_hz, 10.0);
  EXPECT_EQ(o.speed_sigma_m_per_s, 0.05);
  EXPECT_EQ(o.scale_factor_sigma, 0.0);
  EXPECT_EQ(o.lever_arm_b_m, Eigen::Vector3d::Zero());
  EXPECT_TRUE(o.non_holonomic);
  EXPECT_EQ(o.non_holonomic_sigma_m_per_s, 0.1);
  EXPECT_EQ(OdometerJobError(
                OdometerJobJson("INS_GNSS_EKF", R"({"odometer": {"non_holonomic": false}})")),
            "");
}

TEST(OdometerJob, EveryFieldOutsideItsRangeIsRefusedWithItsPath) {
  const struct {
    std::string filter, aiding, field, contains;
  } cases[] = {
      {"INS_GNSS_EKF", R"({"odometer": {"rate_hz": 7}})", "aiding.odometer.rate_hz", "7"},
      {"INS_GNSS_EKF", R"({"odometer": {"speed_sigma_m_per_s": 0}})",
       "aiding.odometer.speed_sigma_m_per_s", "0"},
      {"INS_GNSS_EKF", R"({"odometer": {"scale_factor_sigma_ppm": -1}})",
       "aiding.odometer.scale_factor_sigma_ppm", "-1"},
      {"INS_GNSS_EKF", R"({"odometer": {"scale_factor_sigma_ppm": 200000}})",
       "aiding.odometer.scale_factor_sigma_ppm", "200000"},
      {"INS_GNSS_EKF", R"({"odometer": {"lever_arm_b_m": [1, 2]}})",
       "aiding.odometer.lever_arm_b_m", "2 values"},
      {"INS_GNSS_EKF", R"({"odometer": {"non_holonomic_sigma_m_per_s": 11}})",
       "aiding.odometer.non_holonomic_sigma_m_per_s", "11"},
      {"NONE", R"({"odometer": {}})", "aiding.odometer", "INS_GNSS_EKF"},
  };
  for (const auto& c : cases) {
    const std::string message = OdometerJobError(OdometerJobJson(c.filter, c.aiding));
    EXPECT_EQ(message.rfind(c.field + ": ", 0), 0u) << c.aiding << " -> " << message;
    EXPECT_NE(message.find(c.contains), std::string::npos) << c.aiding << " -> " << message;
  }
}

}  // namespace
}  // namespace driftlab::app
