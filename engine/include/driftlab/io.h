// Motion-file import and CSV export.
//
// Import:
//  - gnss-ins-sim motion-definition CSV (github.com/Aceinna/gnss-ins-sim, README "Motion
//    definition" and the docstring of gnss_ins_sim/sim/ins_sim.py): a header line; the initial
//    state lat (deg), lon (deg), alt (m), vx, vy, vz body (m/s), yaw, pitch, roll (deg); a header
//    line; then one command per line: type (1..5), yaw, pitch, roll (deg, or deg/s for type 1),
//    vx, vy, vz body (m/s, or m/s^2 for type 1), duration (s), GPS visibility (0/1; optional,
//    default 1; driftlab simulates no GNSS and only keeps it). Header lines are recognised as
//    lines whose first field is not a number, so files without them are read too. A blank cell
//    of a command line is 0, as gnss-ins-sim reads it (NaN replaced by 0); the initial-state line
//    must be complete (gnss-ins-sim would start from NaN).
//  - Truth profile in the layout of Groves' motion-profile files (Groves, "Principles of GNSS,
//    Inertial, and Multisensor Integrated Navigation Systems", 2nd ed., MATLAB software,
//    Read_profile.m): one sample per line, time (s), latitude (deg), longitude (deg), height (m),
//    v_N, v_E, v_D (m/s), roll, pitch, yaw (deg); no header in Groves' files, one optional header
//    line accepted here.
// Errors are SpecError whose field is "<file>:<line>" and whose message names the column.
//
// Export: streaming CSV writers with SI units in the column names and every number printed as
// the shortest text that reads back to the same double (exact round trip).
#pragma once

#include <cstdio>
#include <filesystem>
#include <istream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/nav_state.h"
#include "driftlab/output_files.h"
#include "driftlab/simulate.h"
#include "driftlab/trajectory.h"

namespace driftlab {

// Reads a gnss-ins-sim motion-definition file into a MotionSpec (WGS-84, segments of
// GnssInsSimCommand with source "<file name>:<line>", default gnss-ins-sim limits). The initial
// NED velocity is C_b_n v_b from the file's body velocity and attitude.
MotionSpec ReadGnssInsSimMotion(const std::filesystem::path& path);
// Same from a stream; `name` is used in error messages and command sources.
MotionSpec ReadGnssInsSimMotion(std::istream& in, const std::string& name);

// Reads a Groves-layout truth profile (angles converted to radians).
std::vector<TruthProfileSample> ReadTruthProfile(const std::filesystem::path& path);
std::vector<TruthProfileSample> ReadTruthProfile(std::istream& in, const std::string& name);
// A MotionSpec whose whole motion is the profile (initial state = first sample).
MotionSpec TruthProfileMotion(std::vector<TruthProfileSample> samples,
                              EarthModel earth_model = EarthModel::kWgs84);

// Base of the CSV writers: owns the file, writes the header at construction. The rows go to a
// temporary file beside the target (output_files.h), which Close() renames over the target; a
// writer destroyed without Close() (an error, a cancellation) leaves no file behind, so a CSV
// either is complete or does not exist. Throws SpecError naming the file if the target is not a
// regular file, OutputError if it cannot be written.
class CsvFile {
 public:
  CsvFile(const std::filesystem::path& path, const std::string& header);
  ~CsvFile();
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;
  // Flushes, syncs and renames the file into place; reports a write error.
  void Close();

 protected:
  // Appends the numbers as one line.
  void Row(const double* values, int count);

 private:
  std::filesystem::path path_;
  std::unique_ptr<OutputFile> output_;
  std::FILE* file_ = nullptr;
  std::vector<char> buffer_;
};

// truth.csv / nav.csv: t_s, lat_rad, lon_rad, h_m, v_{n,e,d}_m_per_s, roll_rad, pitch_rad, yaw_rad.
class NavStateCsvWriter : public CsvFile {
 public:
  explicit NavStateCsvWriter(const std::filesystem::path& path);
  void Write(const NavState& state);
};
using TruthCsvWriter = NavStateCsvWriter;
using NavCsvWriter = NavStateCsvWriter;

// imu.csv: t_s, increment over (t_{k-1}, t_k] (dtheta_{x,y,z}_rad, dv_{x,y,z}_m_per_s) and point
// sample at t_k (omega_{x,y,z}_rad_per_s, f_{x,y,z}_m_per_s2), body axes.
class ImuCsvWriter : public CsvFile {
 public:
  explicit ImuCsvWriter(const std::filesystem::path& path);
  void Write(double t_s, const ImuIncrement& increment, const ImuSample& sample);
};

// errors.csv: t_s, position error r_{n,e,d}_m, velocity error v_{n,e,d}_m_per_s, Euler-angle
// differences roll/pitch/yaw_rad and the attitude error rotation vector psi_{n,e,d}_rad.
class ErrorsCsvWriter : public CsvFile {
 public:
  explicit ErrorsCsvWriter(const std::filesystem::path& path);
  void Write(double t_s, const NavError& error);
};

// Groves-layout truth profile (degrees, no header), readable by ReadTruthProfile and by Groves'
// MATLAB tools.
class GrovesProfileWriter : public CsvFile {
 public:
  explicit GrovesProfileWriter(const std::filesystem::path& path);
  void Write(const NavState& state);
};

// The files of `driftlab simulate` / `export` in `dir`: truth.csv, imu.csv (what the IMU outputs:
// the measured data when the step has them, else the ideal data), nav.csv, errors.csv and, with
// `ideal_imu`, imu_ideal.csv (the error-free data); one row per output epoch (k = 0 carries the
// zero increment; nav.csv and errors.csv from the navigation start on, when the step has a
// solution).
class SimulationCsvWriters {
 public:
  explicit SimulationCsvWriters(const std::filesystem::path& dir, bool ideal_imu = false);
  void Write(const SimulationStep& step);
  void Close();

 private:
  TruthCsvWriter truth_;
  ImuCsvWriter imu_;
  std::optional<ImuCsvWriter> imu_ideal_;
  NavCsvWriter nav_;
  ErrorsCsvWriter errors_;
};

}  // namespace driftlab
