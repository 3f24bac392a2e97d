// Translation of a job's `sensor` section (driftlab.v1.SensorModel, datasheet units in the field
// names) into the engine's ImuErrorModel (SI), with validation of every field.
//
// Rules: with `preset`, the catalogue model is the starting point and every field that is set
// replaces its value (repeated fields when non-empty); without a preset, unset terms are off.
// Conversions go through the units module (units.h), never through ad-hoc factors. Errors are
// SpecError naming the proto field path, the value and the allowed range:
//   "sensor.gyro.arw_deg_per_sqrt_h: -0.1 is not allowed; allowed: 0 <= arw_deg_per_sqrt_h <= 1000
//    deg/sqrt(h)"
#pragma once

#include <optional>
#include <string>

#include "driftlab/sensor_params.h"
#include "driftlab/v1/job.pb.h"

namespace driftlab::app {

// The job's sensor model, or nullopt when the job has no `sensor` (or an empty one): ideal IMU
// data. Throws SpecError.
std::optional<ImuErrorModel> ToImuErrorModel(const v1::Job& job);

// One SensorModel message whose fields live under `prefix` (e.g. "navigation.ekf.sensor", the
// model a mistuned filter assumes). Throws SpecError naming prefix.field.
ImuErrorModel ToImuErrorModel(const v1::SensorModel& sensor, const std::string& prefix);

}  // namespace driftlab::app

namespace driftlab::app {

// The job's random seed: monte_carlo.seed, default kDefaultSeed.
inline constexpr uint64_t kDefaultSeed = 1;
uint64_t JobSeed(const v1::Job& job);

}  // namespace driftlab::app
