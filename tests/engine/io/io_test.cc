// Motion-file import (gnss-ins-sim, Groves truth profile) and the CSV writers.
#include "driftlab/io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "driftlab/spec_error.h"
#include "support/spec_errors.h"

namespace driftlab {
namespace {

using testing::ErrorOf;

std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("driftlab_io_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

std::vector<std::string> Lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

TEST(GnssInsSimMotion, ReadsTheNinetyDegreeTurnFile) {
  const std::filesystem::path file = kTestData / "gnss_ins_sim_90deg_turn.csv";
  const MotionSpec m = ReadGnssInsSimMotion(file);
  EXPECT_EQ(m.earth_model, EarthModel::kWgs84);
  EXPECT_DOUBLE_EQ(m.initial.llh.lat_rad, 31.9965 * kDeg);
  EXPECT_DOUBLE_EQ(m.initial.llh.lon_rad, 120.004 * kDeg);
  EXPECT_EQ(m.initial.llh.h_m, 0.0);
  EXPECT_DOUBLE_EQ(m.initial.attitude.yaw_rad, 315.0 * kDeg);
  // Body velocity 10 m/s forward at yaw 315 deg: v_eb_n = C_b_n v_b = 10 (cos 315, sin 315, 0).
  EXPECT_NEAR(m.initial.v_eb_n.x(), 10.0 * std::cos(315.0 * kDeg), 1e-14);
  EXPECT_NEAR(m.initial.v_eb_n.y(), 10.0 * std::sin(315.0 * kDeg), 1e-14);
  EXPECT_NEAR(m.initial.v_eb_n.z(), 0.0, 1e-15);
  ASSERT_EQ(m.segments.size(), 3u);
  const auto& turn = std::get<GnssInsSimCommand>(m.segments[1]);
  EXPECT_EQ(turn.type, 1);
  EXPECT_DOUBLE_EQ(turn.euler_ypr.x(), 15.0 * kDeg);  // yaw rate, rad/s
  EXPECT_EQ(turn.duration_s, 6.0);
  EXPECT_FALSE(turn.gps_visible);
  EXPECT_EQ(turn.source, file.string() + ":5");
}

TEST(GnssInsSimMotion, ReadsAllCommandTypesAndAnOptionalGpsColumn) {
  const MotionSpec m = ReadGnssInsSimMotion(kTestData / "gnss_ins_sim_all_types.csv");
  ASSERT_EQ(m.segments.size(), 6u);
  const int types[6] = {1, 2, 3, 4, 5, 1};
  for (size_t i = 0; i < 6; ++i)
    EXPECT_EQ(std::get<GnssInsSimCommand>(m.segments[i]).type, types[i]);
  const auto& c5 = std::get<GnssInsSimCommand>(m.segments[4]);
  EXPECT_DOUBLE_EQ(c5.euler_ypr.y(), 10.0 * kDeg);  // pitch column
  EXPECT_TRUE(c5.gps_visible);                      // 8 columns: visible by default
  EXPECT_FALSE(std::get<GnssInsSimCommand>(m.segments[2]).gps_visible);
}

TEST(GnssInsSimMotion, BadFilesNameFileLineAndColumn) {
  const std::filesystem::path type_file = kTestData / "bad_command_type.csv";
  EXPECT_EQ(ErrorOf([&] { ReadGnssInsSimMotion(type_file); }),
            type_file.string() +
                ":5: column 1 (command type): \"7\" is not allowed; allowed: 1, 2, 3, 4 or 5");
  const std::filesystem::path number_file = kTestData / "bad_initial_number.csv";
  EXPECT_EQ(ErrorOf([&] { ReadGnssInsSimMotion(number_file); }),
            number_file.string() +
                ":2: column 8 (ini pitch (deg)): \"abc\" is not allowed; allowed: a finite number");
  auto from_text = [](const std::string& text) {
    return ErrorOf([&] {
      std::istringstream in(text);
      ReadGnssInsSimMotion(in, "m.csv");
    });
  };
  const std::string head = "h\n32,120,0,0,0,0,0,0,0\nh\n";
  EXPECT_EQ(from_text(head + "1,0,0,0,0,0\n"),
            "m.csv:4: 6 columns in the command line; allowed: 8 to 9 comma-separated columns");
  EXPECT_EQ(from_text(head + "1,0,nan,0,0,0,0,5,1\n"),
            "m.csv:4: column 3 (pitch (deg)): \"nan\" is not allowed; allowed: a finite number");
  EXPECT_EQ(from_text(head + "1,0,0,0,0,0,0,-5,1\n"),
            "m.csv:4: column 8 (command duration (s)): \"-5\" is not allowed; allowed: 0 <= "
            "duration <= 100000 s");
  EXPECT_EQ(from_text(head + "2.5,0,0,0,0,0,0,5,1\n"),
            "m.csv:4: column 1 (command type): \"2.5\" is not allowed; allowed: 1, 2, 3, 4 or 5");
  EXPECT_EQ(from_text(head), "m.csv:3: no command lines; allowed: at least one motion command");
  EXPECT_NE(from_text("h\n95,120,0,0,0,0,0,0,0\nh\n1,0,0,0,0,0,0,5,1\n").find("m.csv:2: column 1"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf([] { ReadGnssInsSimMotion(kTestData / "no_such_file.csv"); }).find("cannot open"),
      std::string::npos);
}

TEST(GnssInsSimMotion, BlankCommandCellsAreZeroAsInGnssInsSim) {
  // gnss-ins-sim's own motion_def-static.csv before commit e7f1c68: `1,0,0,0,0,,,500,0`.
  const MotionSpec m =
      ReadGnssInsSimMotion(kTestData / "gnss_ins_sim" / "motion_def-static-54b4415.csv");
  ASSERT_EQ(m.segments.size(), 1u);
  const auto& c = std::get<GnssInsSimCommand>(m.segments[0]);
  EXPECT_EQ(c.type, 1);
  EXPECT_EQ(c.v_b, Vector3d::Zero());
  EXPECT_EQ(c.duration_s, 500.0);
  EXPECT_FALSE(c.gps_visible);
  std::istringstream blanks("h\n32,120,0,0,0,0,0,0,0\nh\n1,,,,,,,5,\n2,,,,,,,,\n");
  const MotionSpec b = ReadGnssInsSimMotion(blanks, "m.csv");
  ASSERT_EQ(b.segments.size(), 2u);
  EXPECT_EQ(std::get<GnssInsSimCommand>(b.segments[0]).duration_s, 5.0);
  EXPECT_EQ(std::get<GnssInsSimCommand>(b.segments[1]).duration_s, 0.0);  // no step, as there
  // Not blank and not a number stays an error; so does a blank initial state (gnss-ins-sim would
  // start from NaN).
  std::istringstream text("h\n32,120,0,0,0,0,0,0,0\nh\n1,0,0,0,x,0,0,5,1\n");
  EXPECT_EQ(ErrorOf([&] { ReadGnssInsSimMotion(text, "m.csv"); }),
            "m.csv:4: column 5 (vx_body (m/s)): \"x\" is not allowed; allowed: a finite number");
  std::istringstream initial("h\n32,120,,0,0,0,0,0,0\nh\n1,0,0,0,0,0,0,5,1\n");
  EXPECT_EQ(ErrorOf([&] { ReadGnssInsSimMotion(initial, "m.csv"); }),
            "m.csv:2: column 3 (ini alt (m)): \"\" is not allowed; allowed: a finite number");
}

TEST(TruthProfile, ReadsGrovesLayoutWithOptionalHeader) {
  const auto samples = ReadTruthProfile(kTestData / "groves_profile_header.csv");
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_EQ(samples[1].t_s, 0.5);
  EXPECT_DOUBLE_EQ(samples[0].llh.lat_rad, 50.4249580 * kDeg);
  EXPECT_DOUBLE_EQ(samples[0].llh.lon_rad, -3.5957974 * kDeg);
  EXPECT_EQ(samples[0].llh.h_m, 38.8);
  // A static profile generates a static trajectory.
  TrajectoryGenerator g(TruthProfileMotion(samples), 100.0);
  EXPECT_EQ(g.num_steps(), 100);
  EXPECT_TRUE(g.IsStaticAt(0.5));
}

TEST(TruthProfile, BadFilesNameFileLineAndColumn) {
  const std::filesystem::path file = kTestData / "bad_profile_time.csv";
  EXPECT_EQ(ErrorOf([&] { ReadTruthProfile(file); }),
            file.string() +
                ":3: column 1 (time (s)): \"0.1\" is not allowed; allowed: a time "
                "after the previous sample's");
  std::istringstream short_row("0,45,10,100,0,0,0,0,0\n");
  EXPECT_EQ(ErrorOf([&] { ReadTruthProfile(short_row, "p.csv"); }),
            "p.csv:1: 9 columns in the profile line; allowed: 10 comma-separated columns");
  std::istringstream one("0,45,10,100,0,0,0,0,0,0\n");
  EXPECT_NE(ErrorOf([&] { ReadTruthProfile(one, "p.csv"); }).find("1 samples; allowed: at least 2"),
            std::string::npos);
}

TEST(CsvWriters, WriteSiHeadersAndRoundTripEveryDoubleExactly) {
  const std::filesystem::path dir = TempDir("writers");
  NavState s;
  s.t_s = 0.01;
  s.llh = {0.7068583470577035, -0.06585, 123.456789012345};
  s.v_eb_n = Vector3d(1.0 / 3.0, -2e-17, 1e300);
  s.q_b_n = Quaterniond(Eigen::AngleAxisd(0.3, Vector3d(1, 2, 3).normalized()));
  {
    TruthCsvWriter w(dir / "truth.csv");
    w.Write(s);
    w.Close();
  }
  const auto lines = Lines(dir / "truth.csv");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0],
            "t_s,lat_rad,lon_rad,h_m,v_n_m_per_s,v_e_m_per_s,v_d_m_per_s,roll_rad,pitch_rad,"
            "yaw_rad");
  std::istringstream row(lines[1]);
  std::string field;
  std::vector<double> v;
  while (std::getline(row, field, ',')) v.push_back(std::stod(field));
  ASSERT_EQ(v.size(), 10u);
  const EulerAngles e = s.euler();
  const double expected[10] = {s.t_s,        s.llh.lat_rad, s.llh.lon_rad, s.llh.h_m,
                               s.v_eb_n.x(), s.v_eb_n.y(),  s.v_eb_n.z(),  e.roll_rad,
                               e.pitch_rad,  e.yaw_rad};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(v[static_cast<size_t>(i)], expected[i]) << i;
  std::filesystem::remove_all(dir);
}

TEST(CsvWriters, SimulationWritesFourFilesWithOneRowPerEpoch) {
  const std::filesystem::path dir = TempDir("simulation");
  MotionSpec m;
  m.initial.llh = {45 * kDeg, 7 * kDeg, 200.0};
  m.initial.v_eb_n = Vector3d(10, 0, 0);
  m.segments = {ConstantVelocitySegment{0.5}};
  SimulationSpec spec;
  spec.motion = m;
  spec.rate_hz = 100.0;
  {
    SimulationCsvWriters writers(dir);
    RunErrorFreeSimulation(spec, [&](const SimulationStep& step) { writers.Write(step); });
    writers.Close();
  }
  const auto imu = Lines(dir / "imu.csv");
  EXPECT_EQ(imu[0],
            "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_m_per_s,dv_y_m_per_s,dv_z_m_per_s,"
            "omega_x_rad_per_s,omega_y_rad_per_s,omega_z_rad_per_s,f_x_m_per_s2,f_y_m_per_s2,"
            "f_z_m_per_s2");
  EXPECT_EQ(Lines(dir / "errors.csv")[0],
            "t_s,r_n_m,r_e_m,r_d_m,v_n_m_per_s,v_e_m_per_s,v_d_m_per_s,roll_rad,pitch_rad,yaw_rad,"
            "psi_n_rad,psi_e_rad,psi_d_rad");
  for (const char* name : {"truth.csv", "imu.csv", "nav.csv", "errors.csv"}) {
    EXPECT_EQ(Lines(dir / name).size(), 52u) << name;  // header + epochs k = 0..50
  }
  EXPECT_EQ(imu[1].substr(0, 14), "0,0,0,0,0,0,0,");  // k = 0 carries the zero increment
  std::filesystem::remove_all(dir);
}

TEST(CsvWriters, UnwritableDirectoryIsReported) {
  EXPECT_THROW(TruthCsvWriter("/nonexistent_dir_driftlab/truth.csv"), std::runtime_error);
}

}  // namespace
}  // namespace driftlab
