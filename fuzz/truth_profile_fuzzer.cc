// Fuzz target: Groves-layout truth profiles, the motion CSV (fuzz_targets.h): ReadTruthProfile,
// TruthProfileMotion, then the trajectory generator's validation and planning at 100 Hz.
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/io.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzTruthProfile(const uint8_t* data, size_t size) {
  std::istringstream in{std::string(AsText(data, size))};
  try {
    std::vector<TruthProfileSample> samples = ReadTruthProfile(in, "fuzz.csv");
    const MotionSpec motion = TruthProfileMotion(std::move(samples));
    const TrajectoryGenerator generator(motion, 100.0);
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
