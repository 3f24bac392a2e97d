// Sensor models the engine's filter and Monte-Carlo tests share (header-only, namespace
// driftlab::testing).
#pragma once

#include "driftlab/sensors.h"

namespace driftlab::testing {

// The "tactical" preset with only the terms the 15-state error model represents (white noise,
// turn-on bias, Gauss-Markov bias, random walks): flicker, per-run scale factor and misalignment,
// and the range limit switched off.
inline ImuErrorModel TacticalRepresentable() {
  ImuErrorModel model = FindImuPreset("tactical");
  for (TriadErrorParams* p : {&model.gyro, &model.accel}) {
    p->bias_flicker = {};
    p->scale_factor_sigma = 0.0;
    p->misalignment_sigma_rad = 0.0;
    p->range = 0.0;
  }
  return model;
}

}  // namespace driftlab::testing
