// Static-interval detection (Tedaldi et al., ICRA 2014, section IV-A) on simulated tumbles and
// on malformed recordings.
#include "driftlab/calib/static_detection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include "driftlab/calib/tumble.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"
#include "support/spec_errors.h"

namespace driftlab::calib {
namespace {

using testing::ErrorOf;

TEST(StaticDetection, FindsEveryPoseOfANoisyTumbleInsideItsTrueInterval) {
  TumbleSpec spec;
  const Tumble tumble = SimulateTumble(spec, FindImuPreset("adis16470"), 5, 0);
  const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
  ASSERT_EQ(det.intervals.size(), static_cast<size_t>(spec.pose_count));
  // True pose k (k >= 1) spans samples [n_init + k (n_rot + n_pose) - n_pose, ... + n_pose).
  const int64_t n_init = 3000, n_rot = 100, n_pose = 500;
  for (int k = 1; k < spec.pose_count; ++k) {
    const int64_t b = n_init + k * (n_rot + n_pose) - n_pose, e = b + n_pose;
    const StaticInterval& in = det.intervals[k];
    EXPECT_GE(in.begin, b) << k;  // never includes rotating samples
    EXPECT_LE(in.end, e) << k;
    // Loses at most the half window (50 samples) plus a few samples at each end.
    EXPECT_GE(in.count(), n_pose - 2 * 60) << k;
    // Mean specific force is -C_n_b g to within the noise of the mean (ADIS16470 accel noise
    // density 1.5e-3 m/s^2/sqrt(Hz) ~ 1.3e-3 m/s^2 / sqrt(5 s) ~ 7e-4) plus bias/scale errors
    // (< 0.5 m/s^2 for this preset): loose check that the right pose was found.
    EXPECT_LT((in.mean_f_ib_s + tumble.C_b_n[k].transpose() * Eigen::Vector3d(0, 0, 9.806)).norm(),
              0.5)
        << k;
  }
}

TEST(StaticDetection, RecordingThatStartsMovingHasNoInitialStaticPeriod) {
  TumbleSpec spec;
  spec.initial_static_s = 2.0;  // shorter than the 20 s the detector expects
  const Tumble tumble = SimulateTumble(spec, FindImuPreset("adis16470"), 5, 0);
  const std::string msg = ErrorOf([&] { DetectStaticIntervals(tumble.recording, {}); });
  EXPECT_NE(msg.find("no initial static period"), std::string::npos) << msg;
}

TEST(StaticDetection, TooShortRecordingIsAClearError) {
  TumbleSpec spec;
  spec.initial_static_s = 5.0;
  spec.pose_count = 1;
  const Tumble tumble = SimulateTumble(spec, ImuErrorModel{}, 5, 0);
  const std::string msg = ErrorOf([&] { DetectStaticIntervals(tumble.recording, {}); });
  EXPECT_NE(msg.find("shorter than the initial static period"), std::string::npos) << msg;
}

TEST(StaticDetection, NanSampleIsAClearError) {
  TumbleSpec spec;
  Tumble tumble = SimulateTumble(spec, ImuErrorModel{}, 5, 0);
  tumble.recording.f_ib_s[123][1] = std::numeric_limits<double>::quiet_NaN();
  const std::string msg = ErrorOf([&] { DetectStaticIntervals(tumble.recording, {}); });
  EXPECT_NE(msg.find("sample 123 holds a value that is not finite"), std::string::npos) << msg;
}

TEST(StaticDetection, CsvWithWrongColumnCountNamesTheLine) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "driftlab_static_detection_test.csv";
  {
    std::ofstream out(path);
    out << "t_s,gx,gy,gz,ax,ay,az\n0,0,0,0,0,0,-9.8\n0.01,0,0,0,0,-9.8\n";
  }
  const std::string msg = ErrorOf([&] { ReadRawImuCsv(path.string()); });
  EXPECT_NE(msg.find(":3: 6 columns; expected 7"), std::string::npos) << msg;
  {
    std::ofstream out(path);
    out << "0,0,0,0,0,0,-9.8\n0.01,0,0,0,0,nan,-9.8\n";
  }
  const std::string nan_msg = ErrorOf([&] { ReadRawImuCsv(path.string()); });
  EXPECT_NE(nan_msg.find(":2: column 6 is nan"), std::string::npos) << nan_msg;
  std::filesystem::remove(path);
}

TEST(StaticDetection, InvalidOptionNamesTheField) {
  TumbleSpec spec;
  const Tumble tumble = SimulateTumble(spec, ImuErrorModel{}, 5, 0);
  StaticDetectionOptions o;
  o.window_s = -1.0;
  const std::string msg = ErrorOf([&] { DetectStaticIntervals(tumble.recording, o); });
  EXPECT_NE(msg.find("options.window_s: -1"), std::string::npos) << msg;
}

}  // namespace
}  // namespace driftlab::calib
