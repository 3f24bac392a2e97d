// Motion-file import (gnss-ins-sim motion definitions, Groves-layout truth profiles) and the CSV
// writers of `driftlab simulate`. Formats: see io.h.
#include "driftlab/io.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab {

namespace {

std::string_view TrimSpace(std::string_view s) {
  const char* spaces = " \t\r\n\f\v";
  const size_t b = s.find_first_not_of(spaces);
  if (b == std::string_view::npos) return {};
  const size_t e = s.find_last_not_of(spaces);
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> SplitCsv(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    fields.push_back(TrimSpace(line.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  // A trailing comma (spreadsheet export) leaves an empty last field: drop it.
  if (fields.size() > 1 && fields.back().empty()) fields.pop_back();
  return fields;
}

bool ParseDouble(std::string_view text, double* value) {
  if (text.empty()) return false;
  if (text.front() == '+') text.remove_prefix(1);
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size();
}

// A line of a CSV file with its number (1-based) for messages.
struct Line {
  int number = 0;
  std::vector<std::string_view> fields;
  std::string text;
};

class CsvReader {
 public:
  CsvReader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}

  // Next non-blank line; false at the end.
  bool Next(Line* line) {
    std::string text;
    while (ReadLine(in_, &text, name_ + ":" + std::to_string(number_ + 1))) {
      ++number_;
      if (TrimSpace(text).empty()) continue;
      line->number = number_;
      line->text = std::move(text);
      line->fields = SplitCsv(line->text);
      return true;
    }
    if (in_.bad()) Fail(number_, "read error");
    return false;
  }

  // A header or comment line: first field not a number.
  static bool IsHeader(const Line& line) {
    double v;
    return !ParseDouble(line.fields.front(), &v) || line.fields.front().starts_with('#');
  }

  [[noreturn]] void Fail(int line, const std::string& message) const {
    throw SpecError(name_ + ":" + std::to_string(line), message, 0);
  }

  void ExpectColumns(const Line& line, size_t lo, size_t hi, const char* what) const {
    if (line.fields.size() < lo || line.fields.size() > hi) {
      Fail(line.number,
           std::to_string(line.fields.size()) + " columns in the " + what + " line; allowed: " +
               (lo == hi ? std::to_string(lo) : std::to_string(lo) + " to " + std::to_string(hi)) +
               " comma-separated columns");
    }
  }

  // Column `column` (0-based) as a finite number.
  double Number(const Line& line, size_t column, const char* column_name) const {
    double v = 0.0;
    const std::string_view text = line.fields[column];
    if (!ParseDouble(text, &v) || !std::isfinite(v)) {
      Fail(line.number, "column " + std::to_string(column + 1) + " (" + column_name + "): \"" +
                            std::string(text) + "\" is not allowed; allowed: a finite number");
    }
    return v;
  }

  const std::string& name() const { return name_; }

 private:
  std::istream& in_;
  std::string name_;
  int number_ = 0;
};

// A motion or truth-profile file: a regular file of at most kMaxMotionFileBytes (input_files.h).
std::ifstream OpenInput(const std::filesystem::path& path) {
  return OpenInputFile(path, kMaxMotionFileBytes, path.string());
}

const char* const kInitialColumns[9] = {
    "ini lat (deg)",     "ini lon (deg)",     "ini alt (m)",
    "ini vx_body (m/s)", "ini vy_body (m/s)", "ini vz_body (m/s)",
    "ini yaw (deg)",     "ini pitch (deg)",   "ini roll (deg)"};
const char* const kCommandColumns[9] = {
    "command type",  "yaw (deg)",     "pitch (deg)",          "roll (deg)",    "vx_body (m/s)",
    "vy_body (m/s)", "vz_body (m/s)", "command duration (s)", "GPS visibility"};

}  // namespace

// ---- gnss-ins-sim
// ---------------------------------------------------------------------------------

MotionSpec ReadGnssInsSimMotion(std::istream& in, const std::string& name) {
  CsvReader reader(in, name);
  Line line;
  bool found = false;
  while ((found = reader.Next(&line)) && CsvReader::IsHeader(line)) {
  }
  if (!found) reader.Fail(1, "no initial-state line; allowed: a gnss-ins-sim motion definition");
  reader.ExpectColumns(line, 9, 9, "initial-state");
  double v[9];
  for (size_t i = 0; i < 9; ++i) v[i] = reader.Number(line, i, kInitialColumns[i]);
  if (!(std::abs(v[0]) <= 90.0)) {
    reader.Fail(line.number, "column 1 (ini lat (deg)): " + std::to_string(v[0]) +
                                 " is not allowed; allowed: -90 <= lat <= 90 deg");
  }
  MotionSpec motion;
  motion.earth_model = EarthModel::kWgs84;
  motion.initial.llh = Llh{v[0] * kDegToRad, v[1] * kDegToRad, v[2]};
  motion.initial.attitude =
      EulerAngles{v[8] * kDegToRad, v[7] * kDegToRad, v[6] * kDegToRad};  // roll, pitch, yaw
  motion.initial.v_eb_n = EulerToDcm(motion.initial.attitude) * Vector3d(v[3], v[4], v[5]);

  while (reader.Next(&line)) {
    if (CsvReader::IsHeader(line)) continue;
    reader.ExpectColumns(line, 8, 9, "command");
    double c[9];
    c[8] = 1.0;
    // A blank cell is 0, as in gnss-ins-sim: numpy.genfromtxt reads it as NaN and
    // Sim.__parse_motion() (gnss_ins_sim/sim/ins_sim.py) replaces NaN by 0 "to be compatible with
    // older version motion def files" (e.g. motion_def-static.csv before commit e7f1c68:
    // `1,0,0,0,0,,,500,0`). Text that is not a number stays an error.
    for (size_t i = 0; i < line.fields.size(); ++i) {
      c[i] = line.fields[i].empty() ? 0.0 : reader.Number(line, i, kCommandColumns[i]);
    }
    GnssInsSimCommand command;
    if (c[0] != std::round(c[0]) || c[0] < 1.0 || c[0] > 5.0) {
      reader.Fail(line.number, "column 1 (command type): \"" + std::string(line.fields[0]) +
                                   "\" is not allowed; allowed: 1, 2, 3, 4 or 5");
    }
    command.type = static_cast<int>(c[0]);
    if (!(c[7] >= 0.0 && c[7] <= kMaxDuration_s)) {
      reader.Fail(line.number, "column 8 (command duration (s)): \"" + std::string(line.fields[7]) +
                                   "\" is not allowed; allowed: 0 <= duration <= 100000 s");
    }
    if (c[8] != 0.0 && c[8] != 1.0) {
      reader.Fail(line.number, "column 9 (GPS visibility): \"" + std::string(line.fields[8]) +
                                   "\" is not allowed; allowed: 0 or 1");
    }
    command.euler_ypr = Vector3d(c[1], c[2], c[3]) * kDegToRad;
    command.v_b = Vector3d(c[4], c[5], c[6]);
    command.duration_s = c[7];
    command.gps_visible = c[8] != 0.0;
    command.source = name + ":" + std::to_string(line.number);
    motion.segments.push_back(command);
  }
  if (motion.segments.empty()) {
    reader.Fail(line.number, "no command lines; allowed: at least one motion command");
  }
  return motion;
}

MotionSpec ReadGnssInsSimMotion(const std::filesystem::path& path) {
  std::ifstream in = OpenInput(path);
  return ReadGnssInsSimMotion(in, path.string());
}

// ---- Truth profile
// --------------------------------------------------------------------------------

std::vector<TruthProfileSample> ReadTruthProfile(std::istream& in, const std::string& name) {
  static const char* const kColumns[10] = {
      "time (s)",  "latitude (deg)", "longitude (deg)", "height (m)",  "v_N (m/s)",
      "v_E (m/s)", "v_D (m/s)",      "roll (deg)",      "pitch (deg)", "yaw (deg)"};
  CsvReader reader(in, name);
  std::vector<TruthProfileSample> samples;
  Line line;
  bool first = true;
  while (reader.Next(&line)) {
    if (first && CsvReader::IsHeader(line)) {
      first = false;
      continue;
    }
    first = false;
    reader.ExpectColumns(line, 10, 10, "profile");
    double v[10];
    for (size_t i = 0; i < 10; ++i) v[i] = reader.Number(line, i, kColumns[i]);
    if (!(std::abs(v[1]) <= 90.0)) {
      reader.Fail(line.number, "column 2 (latitude (deg)): \"" + std::string(line.fields[1]) +
                                   "\" is not allowed; allowed: -90 <= latitude <= 90 deg");
    }
    if (!samples.empty() && !(v[0] > samples.back().t_s)) {
      reader.Fail(line.number, "column 1 (time (s)): \"" + std::string(line.fields[0]) +
                                   "\" is not allowed; allowed: a time after the previous "
                                   "sample's");
    }
    TruthProfileSample s;
    s.t_s = v[0];
    s.llh = Llh{v[1] * kDegToRad, v[2] * kDegToRad, v[3]};
    s.v_eb_n = Vector3d(v[4], v[5], v[6]);
    s.attitude = EulerAngles{v[7] * kDegToRad, v[8] * kDegToRad, v[9] * kDegToRad};
    samples.push_back(s);
  }
  if (samples.size() < 2) {
    reader.Fail(line.number, std::to_string(samples.size()) +
                                 " samples; allowed: at least 2 lines of time, latitude, "
                                 "longitude, height, v_N, v_E, v_D, roll, pitch, yaw");
  }
  return samples;
}

std::vector<TruthProfileSample> ReadTruthProfile(const std::filesystem::path& path) {
  std::ifstream in = OpenInput(path);
  return ReadTruthProfile(in, path.string());
}

MotionSpec TruthProfileMotion(std::vector<TruthProfileSample> samples, EarthModel earth_model) {
  MotionSpec motion;
  motion.earth_model = earth_model;
  if (!samples.empty()) {
    motion.initial.llh = samples.front().llh;
    motion.initial.v_eb_n = samples.front().v_eb_n;
    motion.initial.attitude = samples.front().attitude;
  }
  motion.truth_profile = std::move(samples);
  return motion;
}

// ---- CSV writers
// ----------------------------------------------------------------------------------

CsvFile::CsvFile(const std::filesystem::path& path, const std::string& header)
    : path_(path), buffer_(1 << 20) {
  output_ = std::make_unique<OutputFile>(path, path.string());
  file_ = output_->stream();
  std::setvbuf(file_, buffer_.data(), _IOFBF, buffer_.size());
  if (!header.empty()) {
    std::fputs(header.c_str(), file_);
    std::fputc('\n', file_);
  }
}

// Without Close(), output_'s destructor removes the temporary file (before buffer_ goes).
CsvFile::~CsvFile() { output_.reset(); }

void CsvFile::Close() {
  if (!output_) return;
  file_ = nullptr;
  output_->Commit();
  output_.reset();
}

void CsvFile::Row(const double* values, int count) {
  // Shortest text that reads back to the same double: exact round trip.
  char line[32 * 20];
  char* p = line;
  char* const end = line + sizeof(line);
  for (int i = 0; i < count; ++i) {
    if (i > 0) *p++ = ',';
    p = std::to_chars(p, end - 1, values[i]).ptr;
  }
  *p++ = '\n';
  if (std::fwrite(line, 1, static_cast<size_t>(p - line), file_) != static_cast<size_t>(p - line)) {
    throw OutputError(path_.string() + ": cannot write: write error (" + std::strerror(errno) +
                      ")");
  }
}

NavStateCsvWriter::NavStateCsvWriter(const std::filesystem::path& path)
    : CsvFile(path,
              "t_s,lat_rad,lon_rad,h_m,v_n_m_per_s,v_e_m_per_s,v_d_m_per_s,roll_rad,pitch_rad,"
              "yaw_rad") {}

void NavStateCsvWriter::Write(const NavState& s) {
  const EulerAngles e = s.euler();
  const double v[10] = {s.t_s,        s.llh.lat_rad, s.llh.lon_rad, s.llh.h_m,   s.v_eb_n.x(),
                        s.v_eb_n.y(), s.v_eb_n.z(),  e.roll_rad,    e.pitch_rad, e.yaw_rad};
  Row(v, 10);
}

ImuCsvWriter::ImuCsvWriter(const std::filesystem::path& path)
    : CsvFile(path,
              "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_m_per_s,dv_y_m_per_s,dv_z_m_per_s,"
              "omega_x_rad_per_s,omega_y_rad_per_s,omega_z_rad_per_s,f_x_m_per_s2,f_y_m_per_s2,"
              "f_z_m_per_s2") {}

void ImuCsvWriter::Write(double t_s, const ImuIncrement& inc, const ImuSample& s) {
  const double v[13] = {t_s,
                        inc.delta_theta_ib_b.x(),
                        inc.delta_theta_ib_b.y(),
                        inc.delta_theta_ib_b.z(),
                        inc.delta_v_ib_b.x(),
                        inc.delta_v_ib_b.y(),
                        inc.delta_v_ib_b.z(),
                        s.omega_ib_b.x(),
                        s.omega_ib_b.y(),
                        s.omega_ib_b.z(),
                        s.f_ib_b.x(),
                        s.f_ib_b.y(),
                        s.f_ib_b.z()};
  Row(v, 13);
}

ErrorsCsvWriter::ErrorsCsvWriter(const std::filesystem::path& path)
    : CsvFile(path,
              "t_s,r_n_m,r_e_m,r_d_m,v_n_m_per_s,v_e_m_per_s,v_d_m_per_s,roll_rad,pitch_rad,"
              "yaw_rad,psi_n_rad,psi_e_rad,psi_d_rad") {}

void ErrorsCsvWriter::Write(double t_s, const NavError& e) {
  const double v[13] = {t_s,
                        e.r_ned_m.x(),
                        e.r_ned_m.y(),
                        e.r_ned_m.z(),
                        e.v_ned_m_per_s.x(),
                        e.v_ned_m_per_s.y(),
                        e.v_ned_m_per_s.z(),
                        e.euler_rad.x(),
                        e.euler_rad.y(),
                        e.euler_rad.z(),
                        e.psi_nb_n_rad.x(),
                        e.psi_nb_n_rad.y(),
                        e.psi_nb_n_rad.z()};
  Row(v, 13);
}

GrovesProfileWriter::GrovesProfileWriter(const std::filesystem::path& path) : CsvFile(path, "") {}

void GrovesProfileWriter::Write(const NavState& s) {
  const EulerAngles e = s.euler();
  const double v[10] = {s.t_s,
                        s.llh.lat_rad * kRadToDeg,
                        s.llh.lon_rad * kRadToDeg,
                        s.llh.h_m,
                        s.v_eb_n.x(),
                        s.v_eb_n.y(),
                        s.v_eb_n.z(),
                        e.roll_rad * kRadToDeg,
                        e.pitch_rad * kRadToDeg,
                        e.yaw_rad * kRadToDeg};
  Row(v, 10);
}

SimulationCsvWriters::SimulationCsvWriters(const std::filesystem::path& dir, bool ideal_imu)
    : truth_(dir / "truth.csv"),
      imu_(dir / "imu.csv"),
      nav_(dir / "nav.csv"),
      errors_(dir / "errors.csv") {
  if (ideal_imu) imu_ideal_.emplace(dir / "imu_ideal.csv");
}

void SimulationCsvWriters::Write(const SimulationStep& step) {
  const double t_s = step.truth->t_s;
  truth_.Write(*step.truth);
  const bool measured = step.measured_increment != nullptr && step.measured_sample != nullptr;
  imu_.Write(t_s, measured ? *step.measured_increment : *step.increment,
             measured ? *step.measured_sample : *step.sample);
  if (imu_ideal_) imu_ideal_->Write(t_s, *step.increment, *step.sample);
  // Before the navigation start (an alignment window) there is no solution.
  if (step.nav == nullptr) return;
  nav_.Write(*step.nav);
  errors_.Write(t_s, *step.error);
}

void SimulationCsvWriters::Close() {
  truth_.Close();
  imu_.Close();
  if (imu_ideal_) imu_ideal_->Close();
  nav_.Close();
  errors_.Close();
}

}  // namespace driftlab
