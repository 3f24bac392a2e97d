// Allan-deviation noise-model fit of a recording (`driftlab allan DATA.csv --fit --out MODEL.json
// [--report REPORT.html]`): reads the CSV columns (default: driftlab imu.csv point samples
// omega_{x,y,z}_rad_per_s and f_{x,y,z}_m_per_s2) and runs app::RunNoiseFit
// (calibration_job.h: overlapping Allan deviation per column, IEEE Std 952 fit per axis and per
// triad with calib/noise_fit.h); prints the fitted terms +- 1 sigma in datasheet units (next to a
// datasheet's figures when one is given), writes the triad fits as a job-schema sensor fragment
// and, with --report, the HTML report (calibration_report.h: ADEV with 95 % CIs and the fitted
// curve per column).
#pragma once

#include <string>
#include <vector>

namespace driftlab::cli {

// Comma-separated column names (--columns), each trimmed of spaces and tabs.
std::vector<std::string> SplitColumnNames(const std::string& text);

struct AllanFitOptions {
  std::string data_path;
  double rate_hz = 0.0;
  // Comma-separated column names; units from the name suffix (_rad_per_s, _deg_per_s,
  // _deg_per_h, _m_per_s2, _g, _mg, _ug; increments _rad, _deg, _m_per_s are divided by
  // 1 / rate). Angular-rate columns form the gyro triad, acceleration columns the accelerometer
  // triad. Empty = the imu.csv columns.
  std::string columns;
  std::string out_path;        // MODEL.json ({"sensor": {...}}); empty = not written
  std::string report_path;     // REPORT.html; empty = not written
  std::string fit_json_path;   // FIT.json: the whole v1.NoiseModelFit (terms with intervals and
                               // tests, goodness of fit, warnings); empty = not written
  std::string datasheet_path;  // datasheet summary to compare with (calib/datasheet.h)
  int points_per_octave = 1;
  std::string bias_model = "flicker";  // flicker | flicker-band | gauss-markov | none
  double flicker_tau_min_s = 0.0;      // 0 = first tau of the curve
  double flicker_tau_max_s = 0.0;      // 0 = last tau
};

// Returns the exit status (commands.h: 0 ok, 1 I/O failure, 2 bad data or options); messages go
// to stderr.
int RunAllanFit(const AllanFitOptions& options);

}  // namespace driftlab::cli
