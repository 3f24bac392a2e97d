// `driftlab datasheet` and the Allan noise-model fit (`driftlab allan --fit`, RunAllanFit) as a
// child process.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <regex>
#include <string>

#include "support/cli_runner.h"

namespace driftlab::testing {
namespace {

double NumberAfter(const std::string& text, const std::string& key) {
  const std::regex re("\"" + key + "\": ([-+0-9.eE]+)");
  std::smatch m;
  if (!std::regex_search(text, m, re)) return NAN;
  return std::stod(m[1].str());
}

TEST(NoiseFitCliTest, DatasheetWritesTheSensorFragmentAndShowsSiValues) {
  Scratch scratch;
  const auto out = scratch.dir() / "model.json";
  const Result r = RunDriftlab(
      {"datasheet", (kCliData / "datasheet_tactical.yaml").string(), "--out", out.string()},
      scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  // 0.15 deg/sqrt(h) = 0.15 * pi / 180 / 60 rad/sqrt(s) = 4.36332e-05 (6 significant digits shown).
  EXPECT_NE(r.out.find("4.36332e-05 rad/sqrt(s)"), std::string::npos) << r.out;
  const std::string json = ReadFile(out);
  EXPECT_NE(json.find("\"sensor\""), std::string::npos);
  EXPECT_EQ(NumberAfter(json, "arw_deg_per_sqrt_h"), 0.15) << json;
  EXPECT_EQ(NumberAfter(json, "bias_instability_deg_per_h"), 3.0) << json;
  EXPECT_EQ(NumberAfter(json, "range_g"), 70.0) << json;
}

TEST(NoiseFitCliTest, DatasheetErrorsNameKeyValueAndAllowedUnits) {
  Scratch scratch;
  const Result r =
      RunDriftlab({"datasheet", (kCliData / "datasheet_wrong_dimension.yaml").string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("gyro.arw: '0.15 deg/h'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("deg/sqrt(h)"), std::string::npos) << r.err;
  const Result u =
      RunDriftlab({"datasheet", (kCliData / "datasheet_unknown_key.yaml").string()}, scratch);
  EXPECT_EQ(u.exit_status, 2);
  EXPECT_NE(u.err.find("accel.bias_stability"), std::string::npos) << u.err;
}

// White gyro noise of known density: N = sigma / sqrt(rate) (sensors.h point samples). 2^17
// samples at 100 Hz: N comes from tau 0.01-100 s with edf ~ 1e5 at the short end, sigma(N) well
// below 1 %; 5 % is the required accuracy.
TEST(NoiseFitCliTest, AllanFitRecoversWhiteNoiseAndWritesTheModel) {
  Scratch scratch;
  const auto csv = scratch.dir() / "imu.csv";
  const double rate_hz = 100.0, arw_deg_per_sqrt_h = 0.5;
  const double n_si = arw_deg_per_sqrt_h * M_PI / 180.0 / 60.0;
  {
    std::ofstream out(csv);
    out << "t_s,omega_x_rad_per_s,omega_y_rad_per_s,omega_z_rad_per_s,f_x_m_per_s2,f_y_m_per_s2,"
           "f_z_m_per_s2\n";
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g(0.0, n_si * std::sqrt(rate_hz));
    std::normal_distribution<double> a(0.0, 1e-3 * std::sqrt(rate_hz));  // 1e-3 m/s/sqrt(s)
    for (int i = 0; i < (1 << 17); ++i) {
      out << i / rate_hz << ',' << g(rng) << ',' << g(rng) << ',' << g(rng) << ',' << a(rng) << ','
          << a(rng) << ',' << a(rng) << '\n';
    }
  }
  const auto model = scratch.dir() / "model.json";
  const Result r =
      RunDriftlab({"allan", csv.string(), "--fit", "--rate", "100", "--out", model.string(),
                   "--datasheet", (kCliData / "datasheet_tactical.yaml").string()},
                  scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("not determined"), std::string::npos) << r.out;  // no B, K, Q, R in data
  EXPECT_NE(r.out.find("datasheet tactical"), std::string::npos) << r.out;
  const std::string json = ReadFile(model);
  EXPECT_NEAR(NumberAfter(json, "arw_deg_per_sqrt_h") / arw_deg_per_sqrt_h, 1.0, 0.05) << json;
  // 1e-3 m/s/sqrt(s) = 0.06 m/s/sqrt(h).
  EXPECT_NEAR(NumberAfter(json, "vrw_m_per_s_per_sqrt_h") / 0.06, 1.0, 0.05) << json;
}

TEST(NoiseFitCliTest, AllanFitRejectsBadDataWithAMessage) {
  Scratch scratch;
  const auto csv = scratch.dir() / "bad.csv";
  std::ofstream(csv) << "t_s,omega_x_rad_per_s\n0,1e-3\n0.01,abc\n";
  const Result r = RunDriftlab(
      {"allan", csv.string(), "--fit", "--rate", "100", "--columns", "omega_x_rad_per_s"}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("'abc'"), std::string::npos) << r.err;
  const Result missing = RunDriftlab({"allan", csv.string(), "--fit", "--rate", "100"}, scratch);
  EXPECT_EQ(missing.exit_status, 2);
  EXPECT_NE(missing.err.find("omega_y_rad_per_s"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace driftlab::testing
