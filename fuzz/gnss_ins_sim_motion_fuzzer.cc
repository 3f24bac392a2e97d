// Fuzz target: gnss-ins-sim motion-definition files (fuzz_targets.h): ReadGnssInsSimMotion, then
// the trajectory generator's validation and planning at 100 Hz, as a job naming the file does.
#include <sstream>
#include <string>

#include "driftlab/io.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzGnssInsSimMotion(const uint8_t* data, size_t size) {
  std::istringstream in{std::string(AsText(data, size))};
  try {
    const MotionSpec motion = ReadGnssInsSimMotion(in, "fuzz.csv");
    const TrajectoryGenerator generator(motion, 100.0);
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
