// The one aiding schedule (aiding.h AidingSchedule): which aid measures at which IMU sample.
#include <algorithm>
#include <utility>

#include "driftlab/aiding.h"
#include "driftlab/spec_error.h"

namespace driftlab {

AidingSchedule::AidingSchedule(AidingSensors sensors, double imu_rate_hz, int64_t first_k,
                               int64_t n, const std::function<bool(double)>& is_static)
    : sensors_(std::move(sensors)), first_k_(first_k), n_(n) {
  if (sensors_.size() > 32) {
    throw SpecError("aiding", std::to_string(sensors_.size()) + " aids", "at most 32");
  }
  static_epochs_.resize(sensors_.size());
  for (size_t i = 0; i < sensors_.size(); ++i) {
    if (!sensors_[i]->OnlyWhileStatic()) continue;
    static_epochs_[i] = StaticEpochs(sensors_[i]->decimation(), imu_rate_hz, first_k, n, is_static);
  }
}

std::vector<int64_t> StaticEpochs(int64_t d, double imu_rate_hz, int64_t first_k, int64_t n,
                                  const std::function<bool(double)>& is_static) {
  std::vector<int64_t> out;
  for (int64_t k = (first_k + d - 1) / d * d; k <= n; k += d) {
    if (is_static(static_cast<double>(k) / imu_rate_hz)) out.push_back(k);
  }
  return out;
}

uint32_t AidingSchedule::Due(int64_t k, double t_s) const {
  if (k < first_k_ || k > n_) return 0;
  uint32_t due = 0;
  for (size_t i = 0; i < sensors_.size(); ++i) {
    const AidingSensor& sensor = *sensors_[i];
    if (k % sensor.decimation() != 0) continue;
    if (sensor.OnlyWhileStatic()) {
      const std::vector<int64_t>& e = static_epochs_[i];
      if (!std::binary_search(e.begin(), e.end(), k)) continue;
    } else if (!sensor.Available(t_s)) {
      continue;
    }
    due |= uint32_t{1} << i;
  }
  return due;
}

double AidingSchedule::MaxEpochRate(size_t i, double imu_rate_hz) const {
  return imu_rate_hz / static_cast<double>(sensors_[i]->decimation());
}

}  // namespace driftlab
