// Fuzz target: raw IMU recordings of the calibration library (fuzz_targets.h): ReadRawImuCsv
// with a time column and with a given rate, then ValidateRecording.
#include <string>

#include "driftlab/calib/static_detection.h"
#include "driftlab/spec_error.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzRawImuCsv(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile(data, size, ".csv");
  for (const double rate_hz : {0.0, 100.0}) {
    try {
      const calib::RawImuRecording recording = calib::ReadRawImuCsv(path, rate_hz);
      calib::ValidateRecording(recording, "fuzz");
    } catch (const SpecError&) {
    }
  }
}

}  // namespace driftlab::fuzz
