// `driftlab export` and `driftlab simulate` with a sensor model: one seeded run's errored IMU data,
// reproducible from (job, seed, run) alone.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
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

// Rows of a CSV file with a header, as numbers.
std::vector<std::vector<double>> ReadCsv(const fs::path& path) {
  std::istringstream text(ReadFile(path));
  std::string line;
  std::getline(text, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(text, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

TEST(Export, WritesTheErroredDataOfOneSeededRun) {
  Scratch scratch;
  const fs::path job = kCliData / "static_gyro_white_noise.json";
  const Result r =
      RunDriftlab({"export", job.string(), "--out", (scratch.dir() / "a").string()}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* file : {"imu.csv", "imu_ideal.csv", "truth.csv", "truth_groves.csv"}) {
    EXPECT_TRUE(fs::exists(scratch.dir() / "a" / file)) << file;
  }
  EXPECT_NE(ReadFile(scratch.dir() / "a" / "run.txt").find("seed: 42\nrun: 0\n"),
            std::string::npos);

  // The measured minus the ideal point samples are the gyro white noise alone: per axis a sample
  // standard deviation of N sqrt(rate_hz) (sensors.h: point samples carry N / sqrt(dt)).
  // N = 0.5 deg/sqrt(h) = 0.5 (pi/180) / 60 rad/sqrt(s). With n = 60001 samples the relative
  // standard error of a sample standard deviation is 1/sqrt(2 (n - 1)) = 0.29 %; the tolerance of
  // 1.2 % is four of those (one of three axes outside 4 sigma: probability 2e-4; seeded anyway).
  const auto measured = ReadCsv(scratch.dir() / "a" / "imu.csv");
  const auto ideal = ReadCsv(scratch.dir() / "a" / "imu_ideal.csv");
  ASSERT_EQ(measured.size(), 60001u);
  ASSERT_EQ(ideal.size(), measured.size());
  const double expected = 0.5 * M_PI / 180.0 / 60.0 * std::sqrt(100.0);
  for (int axis = 0; axis < 3; ++axis) {
    double sum = 0.0;
    double sum_sq = 0.0;
    for (size_t k = 0; k < measured.size(); ++k) {
      const double e = measured[k][7 + axis] - ideal[k][7 + axis];
      sum += e;
      sum_sq += e * e;
    }
    const double n = static_cast<double>(measured.size());
    const double sigma = std::sqrt((sum_sq - sum * sum / n) / (n - 1));
    EXPECT_NEAR(sigma / expected, 1.0, 0.012) << "axis " << axis;
    // The accelerometers have no error terms: measured = ideal exactly.
    for (size_t k = 0; k < measured.size(); k += 997) {
      EXPECT_EQ(measured[k][10 + axis], ideal[k][10 + axis]);
    }
  }
}

TEST(Export, SameSeedAndRunGiveIdenticalFilesOtherRunsDiffer) {
  Scratch scratch;
  const std::string job = (kCliData / "static_gyro_white_noise.json").string();
  auto out = [&scratch](const char* name) { return (scratch.dir() / name).string(); };
  ASSERT_EQ(RunDriftlab({"export", job, "--out", out("a")}, scratch).exit_status, 0);
  ASSERT_EQ(RunDriftlab({"export", job, "--out", out("b"), "--seed", "42"}, scratch).exit_status,
            0);
  ASSERT_EQ(RunDriftlab({"export", job, "--out", out("c"), "--run", "1"}, scratch).exit_status, 0);
  ASSERT_EQ(RunDriftlab({"export", job, "--out", out("d"), "--seed", "43"}, scratch).exit_status,
            0);
  const std::string a = ReadFile(scratch.dir() / "a" / "imu.csv");
  EXPECT_EQ(a, ReadFile(scratch.dir() / "b" / "imu.csv"));
  EXPECT_NE(a, ReadFile(scratch.dir() / "c" / "imu.csv"));
  EXPECT_NE(a, ReadFile(scratch.dir() / "d" / "imu.csv"));
  // The truth does not depend on the sensor's randomness.
  EXPECT_EQ(ReadFile(scratch.dir() / "a" / "truth.csv"),
            ReadFile(scratch.dir() / "c" / "truth.csv"));
}

TEST(Export, SimulateWritesTheSameMeasuredDataAsExport) {
  Scratch scratch;
  const std::string job = (kCliData / "static_gyro_white_noise.json").string();
  ASSERT_EQ(
      RunDriftlab({"export", job, "--out", (scratch.dir() / "e").string()}, scratch).exit_status,
      0);
  const Result r = RunDriftlab({"simulate", job, "--out", (scratch.dir() / "s").string()}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("sensor model custom, seed 42, run 0"), std::string::npos) << r.out;
  EXPECT_EQ(ReadFile(scratch.dir() / "e" / "imu.csv"), ReadFile(scratch.dir() / "s" / "imu.csv"));
  EXPECT_EQ(ReadFile(scratch.dir() / "e" / "imu_ideal.csv"),
            ReadFile(scratch.dir() / "s" / "imu_ideal.csv"));
}

TEST(Export, AJobWithoutASensorModelIsRefused) {
  Scratch scratch;
  const Result r = RunDriftlab({"export", (kExamples / "seed002_straight.json").string(), "--out",
                                (scratch.dir() / "x").string()},
                               scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("error: sensor: (absent) is not allowed"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scratch.dir() / "x"));
}

}  // namespace
