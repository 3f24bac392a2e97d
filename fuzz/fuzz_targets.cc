#include "fuzz_targets.h"

namespace driftlab::fuzz {

const std::vector<FuzzTarget>& FuzzTargets() {
  static const std::vector<FuzzTarget> targets = {
      {"job_json", FuzzJobJson},
      {"job_yaml", FuzzJobYaml},
      {"units", FuzzUnits},
      {"recording_csv", FuzzRecordingCsv},
      {"raw_imu_csv", FuzzRawImuCsv},
      {"gnss_ins_sim_motion", FuzzGnssInsSimMotion},
      {"truth_profile", FuzzTruthProfile},
      {"datasheet", FuzzDatasheet},
      {"result_merge", FuzzResultMerge},
      {"submit_request", FuzzSubmitRequest},
  };
  return targets;
}

}  // namespace driftlab::fuzz
