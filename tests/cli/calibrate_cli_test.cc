// `driftlab calibrate` as a child process: seed 003's reference data, an accelerometer tumble
// written by the test, and the clear failures for bad data.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "support/accel_tumble.h"
#include "support/cli_runner.h"

namespace driftlab::testing {
namespace {

// The number after `"value":` following `"name": "<name>"` in the JSON result.
double ValueOf(const std::string& json, const std::string& name, const std::string& key) {
  const size_t at = json.find("\"" + name + "\"");
  if (at == std::string::npos) return NAN;
  const size_t k = json.find("\"" + key + "\":", at);
  return std::stod(json.substr(k + key.size() + 3));
}

TEST(CalibrateCli, Seed003ReferenceGivesSensitivitiesAndNulls) {
  Scratch scratch;
  const auto out = scratch.dir() / "calib.json";
  const Result r =
      RunDriftlab({"calibrate", "reference", (kCliData / "calib_seed003_gyro.csv").string(),
                   "--input-unit", "deg/s", "--output-unit", "V", "--out", out.string()},
                  scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("x.sensitivity"), std::string::npos) << r.out;
  const std::string json = ReadFile(out);
  // Hand derivation in tests/calib/reference_calibration_test.cc: x 2.01/396 V/(deg/s), null
  // 2.50 V; y null 2.40 V. Least squares is exact to rounding; JSON keeps 17 digits.
  EXPECT_NEAR(ValueOf(json, "x.sensitivity", "value"), 2.01 / 396.0, 1e-12);
  EXPECT_NEAR(ValueOf(json, "x.null", "value"), 2.50, 1e-12);
  EXPECT_NEAR(ValueOf(json, "y.null", "value"), 2.40, 1e-12);
  EXPECT_NE(json.find("\"unit\": \"V/(deg/s)\""), std::string::npos) << json;
}

// Writes a noise-free accelerometer tumble (gyro columns zero) at 50 Hz: 25 s initial static,
// then 13 more poses of 3 s with 1 s linear transitions; raw f = T f_b + b with T lower
// triangular (the calibration frame), so the fit must return T and b.
void WriteAccelTumble(const std::string& path, const double b[3]) {
  const double T[3][3] = {{1.002, 0, 0}, {1e-3, 0.998, 0}, {-2e-3, 1.5e-3, 1.003}};
  const double s = 1 / std::sqrt(3.0), g = 9.80619;  // |f| = WGS-84 normal gravity at 45 deg, 0 m
  const std::vector<std::array<double, 3>> dirs = {
      {0, 0, -1},  {1, 0, 0},   {-1, 0, 0},  {0, 1, 0},  {0, -1, 0},   {0, 0, 1},  {s, s, s},
      {-s, s, -s}, {s, -s, -s}, {-s, -s, s}, {s, s, -s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}};
  std::ofstream out(path);
  out << "t_s,gx,gy,gz,ax,ay,az\n";
  int k = 0;
  auto emit = [&](const std::array<double, 3>& d) {
    double f[3];
    for (int i = 0; i < 3; ++i) {
      f[i] = b[i];
      for (int j = 0; j < 3; ++j) f[i] += T[i][j] * g * d[j];
    }
    char line[200];
    std::snprintf(line, sizeof line, "%.17g,0,0,0,%.17g,%.17g,%.17g\n", k / 50.0, f[0], f[1], f[2]);
    out << line;
    ++k;
  };
  for (int i = 0; i < 25 * 50; ++i) emit(dirs[0]);
  for (size_t p = 1; p < dirs.size(); ++p) {
    for (int i = 1; i <= 50; ++i) {  // transition: not of unit norm, but not static either
      std::array<double, 3> d;
      for (int j = 0; j < 3; ++j) d[j] = dirs[p - 1][j] + (dirs[p][j] - dirs[p - 1][j]) * i / 50.0;
      emit(d);
    }
    for (int i = 0; i < 3 * 50; ++i) emit(dirs[p]);
  }
}

TEST(CalibrateCli, AccelTumbleRecoversBiasAndWritesTheResult) {
  Scratch scratch;
  const std::string data = (scratch.dir() / "tumble.csv").string();
  const double b[3] = {0.05, -0.08, 0.12};
  WriteAccelTumble(data, b);
  const auto out = scratch.dir() / "calib.json";
  const Result r =
      RunDriftlab({"calibrate", "accel", data, "--lat", "45", "--out", out.string()}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("14 static poses"), std::string::npos) << r.out;
  const std::string json = ReadFile(out);
  // Noise-free data: exact to the 6-digit gravity constant above (|delta g| <= 5e-6 m/s^2).
  EXPECT_NEAR(ValueOf(json, "accel.bias.x", "value"), b[0], 1e-4);
  EXPECT_NEAR(ValueOf(json, "accel.bias.z", "value"), b[2], 1e-4);
  EXPECT_NEAR(ValueOf(json, "accel.misalignment.zy", "value"), 1.5e-3, 1e-5);
  EXPECT_NE(json.find("\"kind\": \"accel\""), std::string::npos);
}

TEST(CalibrateCli, WrongColumnCountIsExitTwoWithTheLine) {
  Scratch scratch;
  const std::string data = (scratch.dir() / "bad.csv").string();
  std::ofstream(data) << "t_s,gx,gy,gz,ax,ay,az\n0,0,0,0,0,0,-9.8\n0.01,0,0,0,0,-9.8\n";
  const Result r = RunDriftlab(
      {"calibrate", "imu", data, "--out", (scratch.dir() / "c.json").string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("bad.csv:3: 6 columns; expected 7"), std::string::npos) << r.err;
}

TEST(CalibrateCli, StaticOnlyRecordingHasTooFewPoses) {
  Scratch scratch;
  const std::string data = (scratch.dir() / "static.csv").string();
  {
    std::ofstream out(data);
    for (int k = 0; k < 3000; ++k) {
      out << k * 0.01 << ",0,0,0,0," << 1e-3 * ((k * 7919) % 13 - 6) << ",-9.8\n";
    }
  }
  const Result r = RunDriftlab(
      {"calibrate", "accel", data, "--out", (scratch.dir() / "c.json").string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("too few poses: 1 static pose found"), std::string::npos) << r.err;
}

// Writes AccelTumbleRows with the columns in `order` (indices into t_s, gx, gy, gz, ax, ay, az)
// under the header `header`.
void WriteTumble(const std::string& path, const std::string& header, const std::vector<int>& order,
                 double noise, double clip) {
  const double b[3] = {0.05, -0.08, 0.12};
  std::ofstream out(path);
  out << header << "\n";
  for (const auto& row : AccelTumbleRows(b, noise, clip)) {
    for (size_t i = 0; i < order.size(); ++i) {
      char field[40];
      std::snprintf(field, sizeof field, "%.17g", row[order[i]]);
      out << (i ? "," : "") << field;
    }
    out << "\n";
  }
}

const std::vector<int> kNamedOrder = {0, 1, 2, 3, 4, 5, 6};

TEST(CalibrateCli, ClippedRecordingIsRefusedNamingTheColumn) {
  Scratch scratch;
  const std::string data = (scratch.dir() / "clipped.csv").string();
  // Noise 2 mg; the sensor saturates at 0.8 g = 7.845 m/s^2, below the 1 g of its poses.
  WriteTumble(data, "t_s,gx,gy,gz,ax,ay,az", kNamedOrder, 0.02, 0.8 * 9.80665);
  const auto out = scratch.dir() / "calib.json";
  const Result r =
      RunDriftlab({"calibrate", "accel", data, "--lat", "45", "--out", out.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.out;
  EXPECT_NE(r.err.find("data: column 'a"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("clipped at "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // The same recording unclipped calibrates (noise 2 mg: the flat-top check does not fire).
  WriteTumble(data, "t_s,gx,gy,gz,ax,ay,az", kNamedOrder, 0.02, 0.0);
  const Result ok =
      RunDriftlab({"calibrate", "accel", data, "--lat", "45", "--out", out.string()}, scratch);
  EXPECT_EQ(ok.exit_status, 0) << ok.err;
}

TEST(CalibrateCli, ColumnsAreReadByTheirHeaderNames) {
  Scratch scratch;
  const std::string data = (scratch.dir() / "accel_first.csv").string();
  // Accelerometer columns first, as the header says: read by name, the fit recovers the bias.
  WriteTumble(data, "t_s,ax,ay,az,gx,gy,gz", {0, 4, 5, 6, 1, 2, 3}, 0.0, 0.0);
  const auto out = scratch.dir() / "calib.json";
  const Result r =
      RunDriftlab({"calibrate", "accel", data, "--lat", "45", "--out", out.string()}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << r.out;
  // Noise-free data: exact to the 6-digit gravity constant (|delta g| <= 5e-6 m/s^2).
  EXPECT_NEAR(ValueOf(ReadFile(out), "accel.bias.x", "value"), 0.05, 1e-4);
  // A header that does not name the expected columns is refused, naming what is missing.
  WriteTumble(data, "time,gx,gy,gz,ax,ay,az", kNamedOrder, 0.0, 0.0);
  const Result bad =
      RunDriftlab({"calibrate", "accel", data, "--lat", "45", "--out", out.string()}, scratch);
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_NE(bad.err.find("data: header: time, gx, gy, gz, ax, ay, az (missing t_s) (unknown "
                         "time) is not allowed"),
            std::string::npos)
      << bad.err;
}

}  // namespace
}  // namespace driftlab::testing
