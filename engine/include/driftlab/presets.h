// IMU catalogue: named error models (sensor_params.h, SI units) a job can select instead of
// spelling out every parameter (DESIGN.md "Sensor models", presets).
//
// The catalogue holds
//  * grade presets from the instrument-grade tables of seed 001 ("rate-grade", "industrial",
//    "tactical", "aviation", "navigation"),
//  * the IMU catalogue of seed 002 (Crossbow DMU, Epson, Gladiator Landmark),
//  * the IMUs of seed 000 (FOG IMU of the ship model) and seed 003 (ADXRS300 + ADXL330),
//  * current IMUs from public datasheets (Analog Devices ADIS16470, ADIS16495-1, ADIS16467-1,
//    TDK InvenSense ICM-42688-P, Movella/Xsens MTi-300, Safran STIM300, Honeywell HG1700 and
//    HG9900, Bosch BMI088),
//  * gnss-ins-sim's built-in accuracy levels ("gnss-ins-sim-low", "-mid", "-high") in that tool's
//    own parametrisation (Gauss-Markov bias started at 0, white noise), from its source code.
// Every preset's `description` names its source (seed or datasheet with revision) and lists every
// parameter the source does not give as "assumed: ...", with the reasoning.
//
// Mapping of datasheet terms (presets.cc states the choice per preset):
//  * rate noise density / ARW / VRW / accel noise density -> white_noise_density;
//  * in-run bias instability (Allan minimum) -> bias_flicker.bias_instability = B;
//  * turn-on bias, bias repeatability, "bias" -> turn_on_bias_sigma (1 sigma unless stated);
//  * scale-factor error -> scale_factor_sigma; axis misalignment -> misalignment_sigma_rad;
//  * measurement range -> range; g-sensitivity -> gyro_g_sensitivity (diagonal).
// Names are lowercase words joined by dashes, e.g. "tactical", "adis16470", "stim300".
#pragma once

#include <string_view>
#include <vector>

#include "driftlab/sensor_params.h"

namespace driftlab {

// All presets, in a fixed order (grades, seeds, datasheets). Built once; thread-safe.
const std::vector<ImuErrorModel>& ImuCatalogue();

// The preset named `name`. Throws SpecError("sensor.preset", name, "one of: <names>") for an
// unknown name.
const ImuErrorModel& FindImuPreset(std::string_view name);

}  // namespace driftlab
