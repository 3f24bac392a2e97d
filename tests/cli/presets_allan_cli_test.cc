// `driftlab presets` and `driftlab allan` run as child processes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"

namespace {

namespace fs = std::filesystem;
using driftlab::testing::ReadFile;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665;  // standard gravity (CGPM 1901), exact

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The value of the first `"key": number` inside the JSON object that follows `"object":`
// (objects printed by protobuf's JSON printer; the read-off terms hold no nested objects).
double JsonNumberIn(const std::string& json, const std::string& object, const std::string& key) {
  const size_t at = json.find("\"" + object + "\"");
  if (at == std::string::npos) return NAN;
  const size_t open = json.find('{', at);
  const size_t close = json.find('}', open);
  const std::string body = json.substr(open, close - open);
  const size_t k = body.find("\"" + key + "\": ");
  if (k == std::string::npos) return NAN;
  return std::strtod(body.c_str() + k + key.size() + 4, nullptr);
}

// Names listed by the unknown-preset error: "... allowed: one of: a, b, c".
std::vector<std::string> AllowedPresetNames(const std::string& message) {
  std::vector<std::string> names;
  const std::string marker = "one of: ";
  size_t pos = message.find(marker);
  if (pos == std::string::npos) return names;
  std::string list = message.substr(pos + marker.size());
  while (!list.empty() && (list.back() == '\n' || list.back() == ' ')) list.pop_back();
  std::istringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    const size_t first = name.find_first_not_of(' ');
    names.push_back(name.substr(first));
  }
  return names;
}

TEST(PresetsCli, TableListsEveryCatalogueNameExactlyOnce) {
  Scratch scratch;
  // The engine's own list of names, through the unknown-preset error (exit 2, names the field and
  // the value).
  const Result bad = RunDriftlab({"presets", "no-such-imu"}, scratch);
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_TRUE(Contains(bad.err, "sensor.preset")) << bad.err;
  EXPECT_TRUE(Contains(bad.err, "no-such-imu")) << bad.err;
  const std::vector<std::string> names = AllowedPresetNames(bad.err);
  // Required: 5 grades + 3 seed 002 + seed 000 + seed 003 + at least 8 current IMUs.
  ASSERT_GE(names.size(), 18u) << bad.err;

  const Result table = RunDriftlab({"presets"}, scratch);
  ASSERT_EQ(table.exit_status, 0) << table.err;
  std::istringstream lines(table.out);
  std::string line;
  std::getline(lines, line);
  ASSERT_EQ(line.rfind("NAME", 0), 0u) << line;
  std::vector<std::string> rows;
  while (std::getline(lines, line) && !line.empty()) rows.push_back(line.substr(0, line.find(' ')));
  EXPECT_EQ(rows.size(), names.size());
  EXPECT_EQ(std::set<std::string>(rows.begin(), rows.end()),
            std::set<std::string>(names.begin(), names.end()));
  EXPECT_TRUE(Contains(table.out, std::to_string(names.size()) + " presets")) << table.out;
  for (const char* added : {"bmi088", "stim300", "hg9900"}) {
    EXPECT_TRUE(std::set<std::string>(rows.begin(), rows.end()).count(added)) << added;
  }
}

TEST(PresetsCli, TacticalShowsArwInDegPerSqrtHourAndItsSource) {
  Scratch scratch;
  const Result r = RunDriftlab({"presets", "tactical"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  // Seed 001 tactical column: ARW 0.15 deg/sqrt(h) = 0.0025 (deg/s)/sqrt(Hz) (x 1/60, exact),
  // bias instability 3 deg/h, accel noise 150 ug/sqrt(Hz).
  EXPECT_TRUE(Contains(r.out, "0.15 deg/sqrt(h) = 0.0025 (deg/s)/sqrt(Hz)")) << r.out;
  EXPECT_TRUE(Contains(r.out, "3 deg/h")) << r.out;
  EXPECT_TRUE(Contains(r.out, "150 ug/sqrt(Hz)")) << r.out;
  EXPECT_TRUE(Contains(r.out, "seed 001")) << r.out;
  // SI beside it: 0.15 pi/180/60 = 4.36332e-05 rad/sqrt(s) (6 significant digits).
  EXPECT_TRUE(Contains(r.out, "4.36332e-05 rad/sqrt(s)")) << r.out;
}

TEST(PresetsCli, JsonCarriesSiValuesAndDatasheetStrings) {
  Scratch scratch;
  const Result r = RunDriftlab({"presets", "tactical", "--json"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_TRUE(Contains(r.out, "\"name\": \"tactical\"")) << r.out;
  EXPECT_TRUE(Contains(r.out, "\"datasheet\": \"0.15 deg/sqrt(h)\"")) << r.out;
  // Printed with round-trip precision: equal to the hand conversion within 1e-15 relative.
  // Key order inside a protobuf Struct is not fixed: look inside the "gyro" object.
  const size_t gyro = r.out.find("\"gyro\": {");
  ASSERT_NE(gyro, std::string::npos) << r.out;
  const double n = JsonNumberIn(r.out.substr(gyro), "white_noise_density", "si");
  EXPECT_NEAR(n, 0.15 * kPi / 180.0 / 60.0, 1e-15 * n);
  // The whole catalogue as a list; descriptions with quotes/backslashes would be escaped by the
  // protobuf printer, so every line is either structure or a complete "key": value pair.
  const Result all = RunDriftlab({"presets", "--json"}, scratch);
  ASSERT_EQ(all.exit_status, 0) << all.err;
  EXPECT_TRUE(Contains(all.out, "\"presets\": [")) << all.out.substr(0, 200);
  EXPECT_TRUE(Contains(all.out, "\"name\": \"bmi088\""));
}

// White noise of density N [u/sqrt(s)] sampled as point rates at rate_hz: per-sample standard
// deviation N sqrt(rate_hz) (sensor_params.h: point samples carry N / sqrt(dt)).
std::vector<double> WhiteNoise(double density, double rate_hz, size_t n, uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::normal_distribution<double> normal(0.0, density * std::sqrt(rate_hz));
  std::vector<double> samples(n);
  for (double& x : samples) x = normal(engine);
  return samples;
}

// Overlapping-ADEV equivalent degrees of freedom for white FM (NIST SP 1065 section 5.3 /
// Howe, Allan & Barnes 1981): edf = [3(N-1)/(2m) - 2(N-2)/N] 4m^2/(4m^2+5), N phase points.
double WhiteFmEdf(double n_phase, double m) {
  return (3.0 * (n_phase - 1.0) / (2.0 * m) - 2.0 * (n_phase - 2.0) / n_phase) * 4.0 * m * m /
         (4.0 * m * m + 5.0);
}

// Chi-square quantile by Wilson-Hilferty: nu (1 - 2/(9 nu) + z sqrt(2/(9 nu)))^3; relative error
// below 1e-4 for nu > 100 (Johnson, Kotz & Balakrishnan, Continuous Univariate Distributions,
// vol. 1, ch. 18), negligible against the +-3.6 % interval tested here.
double ChiSquareQuantileWh(double z, double nu) {
  const double a = 2.0 / (9.0 * nu);
  return nu * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

constexpr double kZ975 = 1.959963984540054;  // standard normal 97.5 % quantile

void WriteCsv(const fs::path& path, const std::string& header,
              const std::vector<std::vector<double>>& columns, double rate_hz) {
  std::ofstream out(path);
  out << header << "\n";
  out.precision(17);
  for (size_t k = 0; k < columns[0].size(); ++k) {
    out << static_cast<double>(k) / rate_hz;
    for (const auto& c : columns) out << "," << c[k];
    out << "\n";
  }
}

TEST(AllanCli, WhiteNoiseReadOffLiesInsideTheChiSquareIntervalAtOneSecond) {
  Scratch scratch;
  constexpr double kRateHz = 100.0;
  constexpr size_t kN = 100000;
  const double n_gyro = 0.15 * kPi / 180.0 / 60.0;  // 0.15 deg/sqrt(h) [rad/sqrt(s)]
  const double n_accel = 150e-6 * kG;               // 150 ug/sqrt(Hz) [m/s/sqrt(s)]
  const std::vector<double> gyro = WhiteNoise(n_gyro, kRateHz, kN, 20240901);
  const std::vector<double> accel = WhiteNoise(n_accel, kRateHz, kN, 20240902);
  std::vector<double> gyro_deg_s(kN), accel_mg(kN);
  for (size_t k = 0; k < kN; ++k) {
    gyro_deg_s[k] = gyro[k] * 180.0 / kPi;
    accel_mg[k] = accel[k] / kG * 1e3;
  }
  const fs::path csv = scratch.dir() / "white.csv";
  WriteCsv(csv, "t_s,gyro_x_deg_per_s,acc_x_mg", {gyro_deg_s, accel_mg}, kRateHz);

  // 95 % interval of an ADEV estimate at tau = 1 s (m = 100) for white FM with N = n + 1 phase
  // points: N_true sqrt(chi2_{0.025}/edf) .. N_true sqrt(chi2_{0.975}/edf), edf = 1498 here,
  // i.e. about +-3.6 %. The read-off fits many points of slope -1/2, so it is at least as tight;
  // the tau = 1 s interval is the stated tolerance.
  const double edf = WhiteFmEdf(kN + 1.0, 100.0);
  ASSERT_NEAR(edf, 1498.0, 1.0);
  const double low = std::sqrt(ChiSquareQuantileWh(-kZ975, edf) / edf);
  const double high = std::sqrt(ChiSquareQuantileWh(kZ975, edf) / edf);

  struct Case {
    const char* column;
    double truth;
    const char* printed_unit;
  };
  for (const Case& c : {Case{"gyro_x_deg_per_s", n_gyro, "deg/sqrt(h)"},
                        Case{"acc_x_mg", n_accel, "m/s/sqrt(h)"}}) {
    const fs::path json = scratch.dir() / (std::string(c.column) + ".json");
    const Result r = RunDriftlab(
        {"allan", csv.string(), "--rate", "100", "--columns", c.column, "--out", json.string()},
        scratch);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_TRUE(Contains(r.out, c.printed_unit)) << r.out;
    EXPECT_TRUE(Contains(r.out, "95 % CI")) << r.out;
    const std::string text = ReadFile(json);
    const double n_hat = JsonNumberIn(text, "white_noise", "si");
    EXPECT_GE(n_hat, c.truth * low) << c.column << " N = " << n_hat << ", truth " << c.truth;
    EXPECT_LE(n_hat, c.truth * high) << c.column << " N = " << n_hat << ", truth " << c.truth;
    // The datasheet-unit value printed in the JSON is the same number converted.
    const double n_ds = JsonNumberIn(text, "white_noise", "datasheet_value");
    if (std::string(c.column) == "gyro_x_deg_per_s") {
      EXPECT_NEAR(n_ds, n_hat * 180.0 / kPi * 60.0, 1e-12 * n_ds);
    } else {
      EXPECT_NEAR(n_ds, n_hat * 60.0, 1e-12 * n_ds);
    }
    // Every point is in the JSON: an octave grid from tau0 = 0.01 s to m <= (n - 1) / 2, i.e.
    // m = 1, 2, ..., 32768: 16 points.
    size_t points = 0;
    for (size_t p = text.find("\"tau_s\""); p != std::string::npos;
         p = text.find("\"tau_s\"", p + 1)) {
      ++points;
    }
    EXPECT_EQ(points, 16u);
  }
}

TEST(AllanCli, IncrementColumnsGiveTheSameCurveAsTheRates) {
  // dtheta = omega / rate: the command divides increments by the interval, so the white-noise
  // read-off of the increments equals the rates' to rounding (1e-9 relative covers the decimal
  // text of 17 significant digits and the cumulative sums).
  Scratch scratch;
  constexpr double kRateHz = 200.0;
  const std::vector<double> omega = WhiteNoise(1e-4, kRateHz, 20000, 7);
  std::vector<double> dtheta(omega.size());
  for (size_t k = 0; k < omega.size(); ++k) dtheta[k] = omega[k] / kRateHz;
  const fs::path csv = scratch.dir() / "inc.csv";
  WriteCsv(csv, "t_s,omega_x_rad_per_s,dtheta_x_rad", {omega, dtheta}, kRateHz);
  double n[2];
  const char* columns[2] = {"omega_x_rad_per_s", "dtheta_x_rad"};
  for (int i = 0; i < 2; ++i) {
    const fs::path json = scratch.dir() / (std::string(columns[i]) + ".json");
    const Result r = RunDriftlab(
        {"allan", csv.string(), "--rate", "200", "--columns", columns[i], "--out", json.string()},
        scratch);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    n[i] = JsonNumberIn(ReadFile(json), "white_noise", "si");
  }
  EXPECT_NEAR(n[1], n[0], 1e-9 * n[0]);
}

TEST(AllanCli, DefaultColumnsOfImuCsvAreThePointSamples) {
  Scratch scratch;
  const std::vector<double> x = WhiteNoise(1e-3, 100.0, 1000, 3);
  const fs::path csv = scratch.dir() / "imu.csv";
  WriteCsv(csv,
           "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_m_per_s,dv_y_m_per_s,dv_z_m_per_s,"
           "omega_x_rad_per_s,omega_y_rad_per_s,omega_z_rad_per_s,f_x_m_per_s2,f_y_m_per_s2,"
           "f_z_m_per_s2",
           std::vector<std::vector<double>>(12, x), 100.0);
  const Result r = RunDriftlab({"allan", csv.string(), "--rate", "100"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* c : {"omega_x_rad_per_s", "omega_z_rad_per_s", "f_x_m_per_s2", "f_z_m_per_s2"}) {
    EXPECT_TRUE(Contains(r.out, std::string("column ") + c + ":")) << c;
  }
  EXPECT_FALSE(Contains(r.out, "column dtheta_x_rad")) << r.out;
  EXPECT_FALSE(Contains(r.out, "column t_s")) << r.out;
}

// Runs allan with `args` and expects exit `status` and every `part` in stderr.
void ExpectError(const Scratch& scratch, const std::vector<std::string>& args, int status,
                 const std::vector<std::string>& parts) {
  const Result r = RunDriftlab(args, scratch);
  EXPECT_EQ(r.exit_status, status) << r.err;
  for (const std::string& part : parts) EXPECT_TRUE(Contains(r.err, part)) << part << ": " << r.err;
}

TEST(AllanCli, BadInputNamesTheFieldTheValueAndTheAllowedRange) {
  Scratch scratch;
  const fs::path good = scratch.dir() / "good.csv";
  WriteCsv(good, "t_s,gyro_deg_per_s,raw",
           {WhiteNoise(1.0, 10.0, 100, 1), WhiteNoise(1.0, 10.0, 100, 2)}, 10.0);
  const std::string g = good.string();
  ExpectError(scratch, {"allan", g, "--rate", "0", "--columns", "gyro_deg_per_s"}, 2,
              {"--rate", "0", "> 0"});
  ExpectError(scratch, {"allan", g, "--rate", "-5", "--columns", "gyro_deg_per_s"}, 2,
              {"--rate", "-5", "> 0"});
  ExpectError(scratch, {"allan", g, "--rate", "10", "--columns", "nope"}, 2,
              {"--columns", "'nope'", "gyro_deg_per_s"});
  // "raw" has no unit suffix: --unit is required and the message names the column.
  ExpectError(scratch, {"allan", g, "--rate", "10", "--columns", "raw"}, 2, {"--unit", "'raw'"});
  ExpectError(scratch, {"allan", g, "--rate", "10", "--columns", "raw", "--unit", "m"}, 2,
              {"--unit", "'m'", "angular rate"});
  ExpectError(scratch, {"allan", g, "--rate", "10", "--columns", "raw", "--unit", "furlong/s"}, 2,
              {"--unit", "furlong"});
  const Result with_unit =
      RunDriftlab({"allan", g, "--rate", "10", "--columns", "raw", "--unit", "deg/s"}, scratch);
  EXPECT_EQ(with_unit.exit_status, 0) << with_unit.err;

  const fs::path text = scratch.dir() / "text.csv";
  std::ofstream(text) << "t_s,gyro_deg_per_s\n0,0.1\n0.1,abc\n0.2,0.3\n";
  ExpectError(scratch, {"allan", text.string(), "--rate", "10"}, 2,
              {"text.csv:3", "gyro_deg_per_s", "'abc'", "finite number"});
  const fs::path nan = scratch.dir() / "nan.csv";
  std::ofstream(nan) << "t_s,gyro_deg_per_s\n0,0.1\n0.1,nan\n0.2,0.3\n";
  ExpectError(scratch, {"allan", nan.string(), "--rate", "10"}, 2, {"'nan'", "finite number"});
  const fs::path ragged = scratch.dir() / "ragged.csv";
  std::ofstream(ragged) << "t_s,gyro_deg_per_s\n0,0.1\n0.1\n";
  ExpectError(scratch, {"allan", ragged.string(), "--rate", "10"}, 2,
              {"ragged.csv:3", "1 fields", "2 fields"});
  const fs::path short_file = scratch.dir() / "short.csv";
  std::ofstream(short_file) << "t_s,gyro_deg_per_s\n0,0.1\n0.1,0.2\n";
  ExpectError(scratch, {"allan", short_file.string(), "--rate", "10"}, 2,
              {"gyro_deg_per_s", "2 samples", "at least 3"});
  const std::string missing = (scratch.dir() / "missing.csv").string();
  ExpectError(scratch, {"allan", missing, "--rate", "10"}, 2, {"DATA", "missing.csv"});
  // An --out whose directory cannot take a file is refused before the work (CheckOutputWritable):
  // exit 2 naming --out and the path.
  const std::string bad_out = (scratch.dir() / "no_dir" / "r.json").string();
  ExpectError(scratch,
              {"allan", g, "--rate", "10", "--columns", "gyro_deg_per_s", "--out", bad_out}, 2,
              {"--out", "no_dir"});
}

}  // namespace
