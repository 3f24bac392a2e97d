// ImuErrorModel (SI, sensor_params.h) -> the job schema's sensor section (driftlab.v1.SensorModel,
// datasheet units in the field names): the inverse of sensor_model.h's ToImuErrorModel, used to
// write fitted or datasheet-derived models as job fragments {"sensor": {...}}.
//
// Every conversion goes through the units module (FromSi with the unit of the field's name:
// deg/h, deg/sqrt(h), deg/h/sqrt(h), ppm, mrad, urad, deg/s; mg, ug, m/s/sqrt(h), ug/sqrt(s),
// mm/s, g; g-sensitivity in (deg/h)/g). Terms that are off (0) are left unset; the flicker band
// and the Gauss-Markov tau are written with their term. No preset: the fragment is explicit.
// ToImuErrorModel of the result gives the model back to rounding (~1e-15 relative).
#pragma once

#include <string>

#include "driftlab/sensor_params.h"
#include "driftlab/v1/job.pb.h"

namespace driftlab::app {

v1::SensorModel ToSensorModelProto(const ImuErrorModel& model);

// {"sensor": {...}} as indented JSON with the proto field names.
std::string SensorModelJson(const ImuErrorModel& model);

}  // namespace driftlab::app
