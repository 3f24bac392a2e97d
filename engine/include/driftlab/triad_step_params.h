// Job constants of one sensor triad's error step, flattened for the step written over the lane
// width (engine/src/sensors/triad_step.h, TriadStep): the lockstep runs hold one per triad, and
// TriadErrorSimulator runs the same step at one lane with the same struct. Plain data with no
// library types, so the per-instruction-set kernel files can include it (engine/src/lanes/lane.h
// explains why they must not share inline code). Filled by TriadStepParamsOf (sensors.h) from
// TriadJobConstants.
#pragma once

namespace driftlab {

inline constexpr int kTriadStepMaxFlicker = 24;  // kMaxFlickerComponents (sensors.h)

struct TriadStepParams {
  int independent = 0, gauss_markov = 0, random_walk = 0, asymmetry = 0, n_flicker = 0;
  double independent_sigma = 0.0;  // TriadJobConstants::independent_sigma
  double gm_decay = 0.0, gm_drive_sigma = 0.0, gm_mean_gain = 0.0;
  double gm_integral_w1_gain = 0.0;
  double rw_step_sigma = 0.0;
  double half_asymmetry[3] = {0.0, 0.0, 0.0};
  double flicker_decay[kTriadStepMaxFlicker] = {};
  double flicker_drive_sigma[kTriadStepMaxFlicker] = {};
  int flicker_period_log2[kTriadStepMaxFlicker] = {};
  double range = 0.0, quantization = 0.0;
};

}  // namespace driftlab
