// Calibration and noise-model fitting of a recording held in memory: the one implementation behind
// `driftlab calibrate`, `driftlab allan --fit` and the gRPC Calibration service (DESIGN.md: one
// validator and one code path for the CLI and the server). The CLI reads the CSV into a
// NumericTable; the server assembles it from streamed SampleRows.
//
// Units: as in the CSV files (calibrate: rad/s and m/s^2 or the reference's raw units; noise fit:
// each column's unit from its name suffix, e.g. omega_x_rad_per_s, f_x_m_per_s2, gyro_deg_per_h).
// Results are SI (calibration.proto).
#pragma once

#include <string>
#include <vector>

#include "driftlab/v1/calibration.pb.h"

namespace driftlab::app {

// Numeric rows with named columns (row-major: values.size() == rows * columns.size()).
struct NumericTable {
  std::vector<std::string> columns;
  std::vector<double> values;
  size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
};

// Limits of a CSV recording besides input_files.h's (file size, line length): columns, and the
// length of a column name (the unit-suffix search is bounded by units.h's kMaxUnitTextBytes).
inline constexpr size_t kMaxCsvColumns = 1000;
inline constexpr size_t kMaxCsvColumnNameBytes = 256;

// Reads a CSV file (one header row of names, then numeric rows; '#' lines and empty lines skipped).
// Throws SpecError naming "FILE:LINE" for a non-numeric or non-finite field or a wrong column
// count, and for a header with repeated names or over the limits above; the file must be a regular
// file within kMaxRecordingFileBytes (input_files.h).
NumericTable ReadNumericCsv(const std::string& path);
// A file whose first non-comment line is all numbers has no header: that line is data and the
// columns are named column1, column2, ... (`driftlab calibrate` reads positional columns and
// accepts such files).
//
// Reads only `columns` (in that order) of a file with a header row; every row is still checked
// for its field count. A name missing from the header throws
// SpecError(columns_field, "'name'", "a column of FILE: <header names>") before any row is read.
NumericTable ReadNumericCsv(const std::string& path, const std::vector<std::string>& columns,
                            const std::string& columns_field);

// One column of a table as SI rates, for the Allan deviation: angular rates (gyro) or
// accelerations, or increments of them (angle, velocity) divided by the sample interval 1 / rate_hz
// (the per-interval average rate, allan.h).
struct RateColumn {
  std::string name;
  std::string unit;             // as parsed (units.h syntax): "rad/s", "deg/h", "m/s2", "rad"
  bool gyro = true;             // angle-based (else velocity-based)
  bool increment = false;       // the column holds increments
  std::vector<double> samples;  // SI rates [rad/s] or [m/s^2]
};

// The columns `names` of `table` (empty: driftlab imu.csv's point samples
// omega_{x,y,z}_rad_per_s, f_{x,y,z}_m_per_s2 when all are present, else every column but a time
// column t, t_*, time*) as SI rates. The unit is `unit` when not empty, else the column name's
// suffix: the longest '_'-separated tail that parses (units.h) with "per" for '/', e.g.
// omega_x_rad_per_s -> rad/s, gyro_deg_per_h -> deg/h, acc_mg -> mg. Throws SpecError naming
// columns_field for an unknown column, unit_field for a missing or wrong unit, and
// "<data_name>: column '<name>'" for fewer than 3 samples (two overlapping second differences at
// tau = 1 / rate).
std::vector<RateColumn> SelectRateColumns(const NumericTable& table,
                                          const std::vector<std::string>& names,
                                          const std::string& unit, double rate_hz,
                                          const std::string& data_name,
                                          const std::string& columns_field = "columns",
                                          const std::string& unit_field = "unit");

// The options of `driftlab calibrate` (same names and defaults; calibration.proto
// CalibrateSettings mirrors them for the gRPC API).
struct CalibrateSettings {
  std::string kind;      // accel, gyro, imu or reference
  double rate_hz = 0.0;  // 0: the table has a t_s column
  double lat_deg = 0.0;
  double height_m = 0.0;
  double init_static_s = 20.0;
  double window_s = 1.0;
  double min_pose_s = 2.0;
  std::string loss = "none";  // none, huber, cauchy
  bool matrix = false;        // reference: full 3x3 sensitivity matrix
  std::string input_unit = "input";
  std::string output_unit = "V";
  std::string data_name;  // CalibrationResult.data_file
};

// Validates the settings and the table (columns: [t_s,] gx, gy, gz, ax, ay, az for accel|gyro|imu;
// in_x, in_y, in_z, out_x, out_y, out_z for reference) and runs the fits. Throws SpecError naming
// the field ("kind", "rate_hz", "lat_deg", ...) or saying what is wrong with the data (too few
// poses, poses not spanning the sphere, no motion between poses, NaN, ...).
v1::CalibrationResult RunCalibration(const CalibrateSettings& settings, const NumericTable& table);

// The options of `driftlab allan --fit`.
struct NoiseFitSettings {
  double rate_hz = 0.0;  // > 0
  // Columns to analyse (names with unit suffixes); empty = driftlab imu.csv's point samples when
  // present, else every column but a time column.
  std::vector<std::string> columns;
  std::string bias_model = "flicker";  // flicker | gauss-markov | none
  int points_per_octave = 1;
  double flicker_tau_min_s = 0.0;  // 0 = first tau of the curve
  double flicker_tau_max_s = 0.0;  // 0 = last tau
  std::string datasheet_yaml;      // optional datasheet summary to compare with
  // Names of the datasheet text ("FILE.yaml", for its error messages) and of the data (the
  // model's description).
  std::string datasheet_source = "datasheet";
  std::string data_name = "data";
};

// Allan deviation of every selected column, IEEE Std 952 fit per axis and per triad, the triads
// as a job-schema sensor model, each term with its 1 sigma (and the datasheet's figure when
// given), and the curves with their 95 % intervals and fitted values. Throws SpecError.
// The result's terms hold every fitted term per axis and per triad; a term the data do not
// determine has value 0 and sigma NaN, and a message gives its upper bound. AllanCurve.adev_fit is
// the triad fit (the model written) at each tau. The messages start with the fit tables in
// datasheet units as `driftlab allan --fit` prints them (calib::FormatNoiseFit), one message per
// column and triad.
v1::NoiseModelFit RunNoiseFit(const NoiseFitSettings& settings, const NumericTable& table);

// The files of a fit, the same bytes wherever they are written (the CLI, the server's web pages):
// a calibration result as `driftlab calibrate --out` writes it (protobuf JSON, proto field names,
// every scalar printed), a noise-model fit as `driftlab allan --fit --fit-json` writes it (proto
// field names). Throw SpecError("result", ...) if protobuf cannot print the message.
std::string CalibrationResultToJson(const v1::CalibrationResult& result);
std::string NoiseModelFitToJson(const v1::NoiseModelFit& fit);

}  // namespace driftlab::app
