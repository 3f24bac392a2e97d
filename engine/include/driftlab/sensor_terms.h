// The terms of the IMU error model (sensor_params.h) as the edges of driftlab name them: one row
// per term holding its engine parameter, its job-file field (job.proto GyroModel / AccelModel, the
// unit in the field's name, the allowed range), its key in a datasheet summary (calib/datasheet.h)
// with the dimension a figure must have, how `driftlab presets NAME` prints it, and how the HTML
// report's IMU line names it. The readers and printers of those edges (clients/app sensor_model.cc
// and sensor_model_json.cc, calib/datasheet.cc, clients/cli/presets_command.cc, the report) walk
// this table: a new term is one row here (docs/design-sensor-term.md walks the change).
//
// Units are text of the units module (units.h) and converted only by it; the engine holds them
// here because they name the edges of its own parameters, and includes no protobuf header: the
// job field is its number (the same in GyroModel and AccelModel), which the clients look up in
// the schema by reflection.
#pragma once

#include <span>
#include <string_view>

#include "driftlab/sensor_params.h"
#include "driftlab/units.h"

namespace driftlab {

enum class SensorTriad { kGyro = 0, kAccel = 1 };

// One text per triad.
struct PerTriad {
  std::string_view gyro, accel;
  std::string_view of(SensorTriad t) const { return t == SensorTriad::kGyro ? gyro : accel; }
};

// How many values a term holds and how the job field writes them.
enum class TermShape {
  kScalar,       // 1 value (an optional double field)
  kAxes,         // 3 values x, y, z (a repeated field of 3)
  kOffDiagonal,  // a 3x3 matrix whose off-diagonal elements the job field writes as 6 values in
                 //   row order xy, xz, yx, yz, zx, zy
  kMatrix,       // a 3x3 matrix, written as 3 values (the diagonal) or 9 (row order)
  kFlag,         // an option of another term (an optional bool field)
};

// The number of values a term stores: 1 (scalar, flag), 3 (axes) or 9 (matrices, row order).
int TermValueCount(TermShape shape);

// Dimension of a gyro g-sensitivity: angular rate per acceleration, rad s^-1 / (m s^-2).
inline constexpr Dimension kRatePerAccelerationDimension{2, -2, 2};

struct SensorTerm {
  // ---- Engine parameter (sensor_params.h) ----
  // Its name in TriadErrorParams ("bias_gauss_markov.tau_s"), or in ImuErrorModel for a
  // model-level term ("gyro_g_sensitivity", gyro_only).
  std::string_view param;
  TermShape shape = TermShape::kScalar;
  bool gyro_only = false;  // a model-level term of the gyro triad (g-sensitivity)
  // Element i (row order for matrices) of the term in `model` for triad t; kFlag terms use `flag`.
  double* (*value)(ImuErrorModel* model, SensorTriad t, int i) = nullptr;
  bool* (*flag)(ImuErrorModel* model, SensorTriad t) = nullptr;

  // ---- Job file: field `proto_field` of v1::GyroModel and v1::AccelModel ----
  int proto_field = 0;
  PerTriad job_unit;      // the unit in the field's name ("deg/h", "mg"); for a ratio the
  PerTriad job_per_unit;  //   numerator, and the denominator here ("g" for (deg/h)/g), else ""
  Dimension gyro_dimension, accel_dimension;  // of job_unit (and of a datasheet figure)
  Dimension per_dimension;                    // of job_per_unit
  bool is_signed = false;                     // range [-max, max], else [0, max]
  double gyro_max = 0.0, accel_max = 0.0;     // in job_unit (per job_per_unit)
  // The proto field of the term this one belongs to (a correlation time to its sigma): written
  // only when that term is on (its first value > 0); 0 = independent.
  int written_with = 0;

  // ---- Datasheet summary: the key under gyro: / accel: (alternatives: the same figure) ----
  PerTriad datasheet_key, datasheet_alt_key;  // "" = no key

  // ---- `driftlab presets NAME`: JSON key, row label, datasheet and SI units ----
  std::string_view preset_key, preset_label;  // "" = not printed
  PerTriad preset_unit, preset_si_unit;
  // White noise is printed as a random walk and also as a density in this unit ("" = none).
  PerTriad preset_density_unit;
  // Printed in the triad's bias unit: the gyro's preset_unit, for accelerometers ug below 1 mg of
  // the preset's bias instability and mg above (AccelBiasPrintUnit).
  bool preset_bias_unit = false;

  // ---- HTML report's IMU figures: label and unit (scalars; vectors print their norm) ----
  PerTriad report_label, report_unit;  // "" = not shown

  Dimension dimension(SensorTriad t) const {
    return t == SensorTriad::kGyro ? gyro_dimension : accel_dimension;
  }
  // Dimension of the value in job_unit per job_per_unit, which a datasheet figure must have.
  Dimension figure_dimension(SensorTriad t) const {
    const Dimension d = dimension(t);
    if (job_per_unit.of(t).empty()) return d;
    return {d.angle2 - per_dimension.angle2, d.length2 - per_dimension.length2,
            d.time2 - per_dimension.time2};
  }
  double max(SensorTriad t) const { return t == SensorTriad::kGyro ? gyro_max : accel_max; }
  bool applies_to(SensorTriad t) const { return !gyro_only || t == SensorTriad::kGyro; }
};

// Every term, in the order the presets print them (noise, biases, scale factor, misalignment,
// quantization, range; model-level terms last).
std::span<const SensorTerm> SensorTerms();

// The term of job field `proto_field`, or nullptr.
const SensorTerm* SensorTermByField(int proto_field);

// Value i of `term` in `model` (triad t), and its assignment.
double TermValue(const SensorTerm& term, const ImuErrorModel& model, SensorTriad t, int i);
void SetTermValue(const SensorTerm& term, ImuErrorModel* model, SensorTriad t, int i, double v);

// Job-field value -> SI and back, through the units module. A ratio unit converts with one factor:
// value * (ToSi(1, job_unit) / ToSi(1, job_per_unit)). `field_path` names the field in errors.
double JobValueToSi(const SensorTerm& term, SensorTriad t, double value,
                    std::string_view field_path);
double JobValueFromSi(const SensorTerm& term, SensorTriad t, double value_si);
// The job unit as text for messages ("deg/h", "deg/h/g").
std::string JobUnitText(const SensorTerm& term, SensorTriad t);

// The accelerometer bias unit of `presets` for a preset whose bias instability is
// bias_instability_si: "ug" below 1 mg, "mg" from 1 mg up (datasheet habit).
std::string_view AccelBiasPrintUnit(double bias_instability_si);

}  // namespace driftlab
