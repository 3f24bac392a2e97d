// Datasheet -> error model: a datasheet summary file holds the figures of an IMU's datasheet with
// their units as printed ("0.15 deg/√h", "25 µg/√Hz", "±450 deg/s"); this module converts them
// through the units module (units.h) into an ImuErrorModel (SI, sensor_params.h) with the mapping
// of presets.h, and lists every derived SI value.
//
// File format: YAML (any form: block or flow mappings, multi-line flow mappings, comments, quotes),
// one document, a mapping of name, description, gyro, accel; gyro and accel map keys to scalars:
//
//   name: stim300                       # optional, the model's name
//   description: "STIM300 rev. 9 ..."   # optional
//   gyro:
//     arw: "0.15 deg/√h"                # or rate_noise_density: "0.0025 (deg/s)/√Hz"
//     bias_instability: "0.5 deg/h"
//     range: "±400 deg/s"
//   accel: {vrw: "0.06 m/s/√h", bias_instability: "0.05 mg", range: "±10 g"}
//
// Keys of `gyro` and `accel`: the datasheet keys of the sensor-term table (sensor_terms.h,
// SensorTerm::datasheet_key and datasheet_alt_key: arw | rate_noise_density, bias_instability,
// bias_instability_tau_min/_max, turn_on_bias, gauss_markov_sigma/_tau, rate_random_walk,
// scale_factor, misalignment, quantization, range, g_sensitivity; accel: vrw | noise_density,
// acceleration_random_walk, ... and no g_sensitivity), each setting its term's parameter; a
// figure must have the term's dimension in any unit the units module knows (docs/calibration.md
// lists them with examples). A matrix term (g-sensitivity) takes its figure on the diagonal.
// Every figure is a magnitude (a leading "±", "+-" or "+/-" as printed is accepted); a negative
// value, an unknown key, a unit of the wrong dimension or a malformed number is a SpecError naming
// the key path ("gyro.arw"), the text and the allowed units. Unknown keys list the allowed ones.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/sensor_params.h"
#include "driftlab/units.h"

namespace driftlab::calib {

// One converted datasheet figure.
struct DatasheetValue {
  std::string key;   // "gyro.arw"
  std::string text;  // as written, "0.15 deg/√h"
  double value_si = 0.0;
  std::string si_unit;  // "rad/sqrt(s)"
  std::string field;    // model field, "gyro.white_noise_density"
};

struct DatasheetModel {
  ImuErrorModel model;
  std::vector<DatasheetValue> values;  // in file order
};

// Entries of a parsed file: "name", "description", "gyro.<key>", "accel.<key>" with their text
// and the line they came from (for messages).
struct DatasheetEntry {
  std::string key;
  std::string text;
  int line = 0;
};

// Parses the YAML above (yaml-cpp). `source` names the text in messages ("file.yaml:12"). Throws
// SpecError for a syntax error, an empty text or one without figures, several documents, a tag, a
// duplicate key, a list or mapping where a figure belongs, or a top-level key other than name,
// description, gyro, accel.
std::vector<DatasheetEntry> ParseDatasheetText(std::string_view text, std::string_view source);

// Converts entries to the model and validates it (ValidateImuErrorModel). Throws SpecError.
DatasheetModel DatasheetToModel(const std::vector<DatasheetEntry>& entries);

// Reads and converts a datasheet file. Throws SpecError (also for an unreadable file).
DatasheetModel LoadDatasheet(const std::filesystem::path& path);

// The SI unit text of a dimension used here ("rad/sqrt(s)", "m/s^2", ...).
std::string SiUnitText(Dimension dimension);

}  // namespace driftlab::calib
