#include "driftlab/calib/static_detection.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <string_view>

#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

// Splits `line` at commas (and trims blanks); returns false if a field is not a number.
bool ParseNumbers(std::string_view line, std::vector<double>* values, size_t* bad_column) {
  values->clear();
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    std::string_view field = line.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!field.empty() && (field.front() == ' ' || field.front() == '\t'))
      field.remove_prefix(1);
    while (!field.empty() &&
           (field.back() == ' ' || field.back() == '\t' || field.back() == '\r')) {
      field.remove_suffix(1);
    }
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
    if (field.empty() || ec != std::errc() || ptr != field.data() + field.size()) {
      *bad_column = values->size() + 1;
      return false;
    }
    values->push_back(v);
    if (comma == std::string_view::npos) return true;
    start = comma + 1;
  }
}

void CheckOption(double value, double min_exclusive, double max, const std::string& field) {
  if (!std::isfinite(value) || value <= min_exclusive || value > max) {
    throw SpecError("options." + field, fmt::format("{}", value),
                    fmt::format("({}, {}]", min_exclusive, max));
  }
}

}  // namespace

void ValidateRecording(const RawImuRecording& r, const std::string& what) {
  if (r.omega_ib_s.size() != r.size() || r.f_ib_s.size() != r.size()) {
    throw SpecError(what, "time, gyro and accelerometer columns differ in length", 0);
  }
  if (r.size() < 2) {
    throw SpecError(what, fmt::format("{} samples; need at least 2", r.size()), 0);
  }
  for (size_t k = 0; k < r.size(); ++k) {
    if (!std::isfinite(r.t_s[k]) || !r.omega_ib_s[k].allFinite() || !r.f_ib_s[k].allFinite()) {
      throw SpecError(what, fmt::format("sample {} holds a value that is not finite (NaN/inf)", k),
                      0);
    }
    if (k > 0 && !(r.t_s[k] > r.t_s[k - 1])) {
      throw SpecError(what,
                      fmt::format("time does not increase at sample {} ({} s after {} s)", k,
                                  r.t_s[k], r.t_s[k - 1]),
                      0);
    }
  }
}

RawImuRecording ReadRawImuCsv(const std::string& path, double rate_hz) {
  if (!(rate_hz >= 0.0) || !std::isfinite(rate_hz)) {
    throw SpecError("--rate", fmt::format("{}", rate_hz), "> 0 Hz, or 0 for a time column");
  }
  std::ifstream in = OpenInputFile(path, kMaxRecordingFileBytes, path);
  const size_t columns = rate_hz > 0.0 ? 6 : 7;
  RawImuRecording r;
  std::string line;
  std::vector<double> v;
  size_t line_no = 0;
  bool first_data_line = true;
  while (ReadLine(in, &line, path + ":" + std::to_string(line_no + 1))) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) {
      continue;
    }
    size_t bad_column = 0;
    if (!ParseNumbers(line, &v, &bad_column)) {
      if (first_data_line) {  // header
        first_data_line = false;
        continue;
      }
      throw SpecError(fmt::format("{}:{}", path, line_no),
                      fmt::format("column {} is not a number", bad_column), 0);
    }
    first_data_line = false;
    if (v.size() != columns) {
      throw SpecError(fmt::format("{}:{}", path, line_no),
                      fmt::format("{} columns; expected {} ({})", v.size(), columns,
                                  columns == 7 ? "t_s, gx, gy, gz [rad/s], ax, ay, az [m/s^2]"
                                               : "gx, gy, gz [rad/s], ax, ay, az [m/s^2] with "
                                                 "--rate"),
                      0);
    }
    for (size_t c = 0; c < v.size(); ++c) {
      if (!std::isfinite(v[c])) {
        throw SpecError(fmt::format("{}:{}", path, line_no),
                        fmt::format("column {} is {} (not a finite number)", c + 1, v[c]), 0);
      }
    }
    const size_t o = columns - 6;
    const double t = o ? v[0] : static_cast<double>(r.size()) / rate_hz;
    if (!r.t_s.empty() && !(t > r.t_s.back())) {
      throw SpecError(fmt::format("{}:{}", path, line_no),
                      fmt::format("time {} s does not increase (previous {} s)", t, r.t_s.back()),
                      0);
    }
    r.t_s.push_back(t);
    r.omega_ib_s.emplace_back(v[o], v[o + 1], v[o + 2]);
    r.f_ib_s.emplace_back(v[o + 3], v[o + 4], v[o + 5]);
  }
  if (r.size() < 2) {
    throw SpecError(path, fmt::format("{} data rows; a recording needs many more", r.size()), 0);
  }
  return r;
}

StaticDetection DetectStaticIntervals(const RawImuRecording& r, const StaticDetectionOptions& o) {
  CheckOption(o.init_static_s, 0.0, 1e6, "init_static_s");
  CheckOption(o.window_s, 0.0, 1e3, "window_s");
  CheckOption(o.threshold_factor, 1.0, 1e6, "threshold_factor");
  CheckOption(o.min_pose_s, 0.0, 1e6, "min_pose_s");
  ValidateRecording(r, "data");
  const int64_t n = static_cast<int64_t>(r.size());
  StaticDetection out;
  out.rate_hz = static_cast<double>(n - 1) / (r.t_s.back() - r.t_s.front());
  const int64_t half = std::max<int64_t>(2, std::llround(0.5 * o.window_s * out.rate_hz));
  const int64_t n_init = std::llround(o.init_static_s * out.rate_hz);
  if (n_init + 2 * half + 1 > n) {
    throw SpecError("data",
                    fmt::format("recording of {:.3g} s is shorter than the initial static period "
                                "({} s) plus one window ({} s)",
                                r.t_s.back() - r.t_s.front(), o.init_static_s, o.window_s),
                    0);
  }
  // Two-pass variance of each window (exact to rounding; prefix sums of squares would cancel).
  auto variance_norm = [&](int64_t b, int64_t e) {  // [b, e)
    const double m = static_cast<double>(e - b);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int64_t k = b; k < e; ++k) mean += r.f_ib_s[k];
    mean /= m;
    Eigen::Vector3d var = Eigen::Vector3d::Zero();
    for (int64_t k = b; k < e; ++k) var += (r.f_ib_s[k] - mean).cwiseAbs2();
    return (var / (m - 1.0)).norm();
  };
  out.init_variance_norm = variance_norm(0, n_init);
  // Floor for noise-free (simulated) data: 1e-12 (m/s^2)^2, i.e. 1e-6 m/s^2 standard deviation.
  out.threshold = std::max(o.threshold_factor * out.init_variance_norm, 1e-12);
  // The initial period must itself be static: every window inside it below the threshold.
  // A static period has windows of nearly equal variance (relative spread ~sqrt(2 / window
  // samples)); motion inside it makes some windows far noisier than the quietest ones.
  double init_max = 0.0, init_min = std::numeric_limits<double>::infinity();
  for (int64_t k = half; k + half < n_init; ++k) {
    const double v = variance_norm(k - half, k + half + 1);
    init_max = std::max(init_max, v);
    init_min = std::min(init_min, v);
  }
  if (init_max > std::max(o.threshold_factor * init_min, 1e-12) || init_max > out.threshold) {
    throw SpecError("data",
                    fmt::format("no initial static period: the accelerometer moving variance in "
                                "the first {} s ranges from {:.3g} to {:.3g} (m/s^2)^2, more than "
                                "a factor {}; start the recording with the IMU at rest",
                                o.init_static_s, init_min, init_max, o.threshold_factor),
                    0);
  }
  const int64_t min_count = std::max<int64_t>(2, std::llround(o.min_pose_s * out.rate_hz));
  auto close_interval = [&](int64_t b, int64_t e) {
    if (e - b < min_count) return;
    StaticInterval in;
    in.begin = b;
    in.end = e;
    in.t_begin_s = r.t_s[b];
    in.t_end_s = r.t_s[e - 1];
    Eigen::Vector3d sf = Eigen::Vector3d::Zero(), sw = Eigen::Vector3d::Zero();
    for (int64_t k = b; k < e; ++k) {
      sf += r.f_ib_s[k];
      sw += r.omega_ib_s[k];
    }
    const double m = static_cast<double>(e - b);
    in.mean_f_ib_s = sf / m;
    in.mean_omega_ib_s = sw / m;
    Eigen::Vector3d vf = Eigen::Vector3d::Zero(), vw = Eigen::Vector3d::Zero();
    for (int64_t k = b; k < e; ++k) {
      vf += (r.f_ib_s[k] - in.mean_f_ib_s).cwiseAbs2();
      vw += (r.omega_ib_s[k] - in.mean_omega_ib_s).cwiseAbs2();
    }
    in.std_f_ib_s = (vf / (m - 1.0)).cwiseSqrt();
    in.std_omega_ib_s = (vw / (m - 1.0)).cwiseSqrt();
    out.intervals.push_back(in);
  };
  // Samples within `half` of either end use the initial-period rule (start) or are not static
  // (end: no full window).
  int64_t run_begin = 0;
  bool in_run = true;
  for (int64_t k = half; k < n; ++k) {
    const bool is_static =
        k + half < n && (k < n_init || variance_norm(k - half, k + half + 1) < out.threshold);
    if (is_static && !in_run) {
      run_begin = k;
      in_run = true;
    } else if (!is_static && in_run) {
      close_interval(run_begin, k);
      in_run = false;
    }
  }
  if (in_run) close_interval(run_begin, n - half);
  return out;
}

}  // namespace driftlab::calib
