// Fuzz target: recording CSV files as `calibrate`, `allan` and `allan --fit` read them
// (fuzz_targets.h): ReadNumericCsv, both overloads, then the unit of each column from its name
// (SelectRateColumns), as the noise fit does.
#include <string>
#include <vector>

#include "driftlab/app/calibration_job.h"
#include "driftlab/spec_error.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzRecordingCsv(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile(data, size, ".csv");
  try {
    app::ReadNumericCsv(path, {"t_s", "omega_x_rad_per_s"}, "columns");
  } catch (const SpecError&) {
  }
  app::NumericTable table;
  try {
    table = app::ReadNumericCsv(path);
  } catch (const SpecError&) {
    return;
  }
  try {
    app::SelectRateColumns(table, {}, "", 100.0, "fuzz");
  } catch (const SpecError&) {
  }
  try {
    app::SelectRateColumns(table, {}, "deg/h", 100.0, "fuzz");
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
