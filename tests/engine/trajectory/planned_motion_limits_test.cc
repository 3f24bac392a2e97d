// Limits of the planned motion whatever its source: segments, gnss-ins-sim commands and truth
// profiles are refused by the Monte Carlo where the Euler angles break down (|pitch| >= 89.9 deg),
// and by the generator where the implied
// body rate or acceleration exceeds the generator's limits, where a turn's radius implies a rate
// beyond the rate limit, and where a truth profile's positions disagree with its velocities.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

#include "driftlab/io.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/motion_builders.h"
#include "support/small_monte_carlo_job.h"

namespace driftlab {
namespace {

constexpr double kDeg = M_PI / 180.0;

MotionSpec Moving(double speed_m_per_s) {
  MotionSpec m;
  m.initial.llh = {40.0 * kDeg, 10.0 * kDeg, 100.0};
  m.initial.v_eb_n = Vector3d(speed_m_per_s, 0.0, 0.0);
  return m;
}

// The SpecError of constructing a generator; fails the test if the motion is accepted.
std::string RejectionOf(const MotionSpec& motion, double rate_hz) {
  try {
    TrajectoryGenerator generator(motion, rate_hz);
  } catch (const SpecError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

void ExpectContains(const std::string& message, std::initializer_list<std::string> parts) {
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "message: " << message << "\nmissing: " << part;
  }
}

TEST(PlannedMotionLimits, TurnRadiusImplyingARateAbove720DegPerSecondIsRefusedNamingTheRadius) {
  MotionSpec m = Moving(10.0);
  TurnSegment turn;
  turn.radius_m = 1e-9;  // at 10 m/s: 1e10 rad/s, the 90 deg turn inside one sample
  turn.angle_rad = 90.0 * kDeg;
  turn.transition_s = 1.0;
  m.segments = {ConstantVelocitySegment{5.0}, turn};
  ExpectContains(RejectionOf(m, 100.0),
                 {"segments[1].turn.radius_m", "1e-09", "radius_m >= 0.795", "720 deg/s"});
  // The smallest radius allowed at 10 m/s, 10 / (4 pi) = 0.796 m (just above it), is accepted.
  turn.radius_m = 0.8;
  turn.transition_s = 0.05;  // the ramps alone turn |rate| x transition_s <= 36 deg
  m.segments = {ConstantVelocitySegment{5.0}, turn};
  EXPECT_NO_THROW(TrajectoryGenerator(m, 100.0));
}

// The first place where the motion's pitch reaches +-89.9 deg; fails the test if it never does.
TrajectoryGenerator::EulerSingularity SingularityOf(const MotionSpec& motion) {
  const TrajectoryGenerator generator(motion, 100.0);
  if (!generator.euler_singularity()) {
    ADD_FAILURE() << "no Euler singularity";
    return {};
  }
  return *generator.euler_singularity();
}

// A Monte Carlo on `motion`: refused by validation, with the message of the singularity.
void ExpectMonteCarloRefused(const MotionSpec& motion, std::initializer_list<std::string> parts) {
  MonteCarloSpec spec = testing::SmallMonteCarloJob();
  spec.simulation.motion = motion;
  spec.checkpoint_times_s.clear();
  try {
    ValidateMonteCarloSpec(spec);
    ADD_FAILURE() << "Monte Carlo accepted";
  } catch (const SpecError& e) {
    ExpectContains(e.what(), parts);
  }
}

// The truth and the IMU data are valid through +-90 deg pitch (gnss-ins-sim's own magnetometer-
// calibration demo goes there); the Monte Carlo, whose roll and yaw error statistics would mean
// nothing there, refuses it naming the command's line.
TEST(PlannedMotionLimits, GnssInsSimCommandPitchingThroughNinetyDegreesIsRefusedByTheMonteCarlo) {
  MotionSpec m = Moving(0.0);
  GnssInsSimCommand c;
  c.type = 1;
  c.euler_ypr = Vector3d(0.0, 10.0 * kDeg, 0.0);  // pitch rate 10 deg/s for 12 s: ~118 deg
  c.duration_s = 12.0;
  c.source = "loop.csv:3";
  m.segments = {ConstantVelocitySegment{1.0}, c};
  const TrajectoryGenerator::EulerSingularity singular = SingularityOf(m);
  EXPECT_EQ(singular.field, "loop.csv:3");
  ExpectContains(singular.message, {"reaches pitch 89.9", "|pitch| < 89.9 deg"});
  ExpectMonteCarloRefused(m, {"loop.csv:3", "reaches pitch 89.9", "|pitch| < 89.9 deg"});
  // 8 s reach ~78 deg (the low-pass start lags 0.1 s): no singularity, the Monte Carlo accepted.
  m.segments[1] = [&] {
    GnssInsSimCommand shorter = c;
    shorter.duration_s = 8.0;
    return shorter;
  }();
  EXPECT_FALSE(TrajectoryGenerator(m, 100.0).euler_singularity().has_value());
  MonteCarloSpec spec = testing::SmallMonteCarloJob();
  spec.simulation.motion = m;
  spec.checkpoint_times_s.clear();
  EXPECT_NO_THROW(ValidateMonteCarloSpec(spec));
}

std::vector<TruthProfileSample> StillProfile(int n, double dt_s) {
  std::vector<TruthProfileSample> samples;
  for (int i = 0; i < n; ++i) {
    TruthProfileSample s;
    s.t_s = i * dt_s;
    s.llh = {40.0 * kDeg, 10.0 * kDeg, 100.0};
    samples.push_back(s);
  }
  return samples;
}

TEST(PlannedMotionLimits, TruthProfileReachingPitchNinetyIsRefusedByTheMonteCarloNamingTheSample) {
  std::vector<TruthProfileSample> samples = StillProfile(21, 0.1);
  for (TruthProfileSample& s : samples) s.attitude.pitch_rad = 1.0 * s.t_s;  // 1 rad/s to 2 rad
  // Pitch 89.9 deg = 1.5691 rad is passed between t = 1.5 s and 1.6 s: sample 15's interval,
  // checked at its 11 sub-steps (the first past 1.5691 rad: t = 1.5727 s, 90.11 deg).
  const MotionSpec motion = TruthProfileMotion(samples);
  EXPECT_EQ(SingularityOf(motion).field, "motion.truth_profile[15]");
  ExpectMonteCarloRefused(motion, {"truth_profile[15]", "reaches pitch 90.1", "t = 1.57"});
}

TEST(PlannedMotionLimits, TruthProfileSpinningAbove100RadPerSecondIsRefused) {
  std::vector<TruthProfileSample> samples = StillProfile(11, 0.01);
  for (TruthProfileSample& s : samples) s.attitude.yaw_rad = 200.0 * s.t_s;  // 2 rad per sample
  ExpectContains(RejectionOf(TruthProfileMotion(samples), 100.0),
                 {"truth_profile[0]", "turns at 11459", "at most 5729.5779"});
}

TEST(PlannedMotionLimits, TruthProfileAcceleratingAbove1000MetresPerSecondSquaredIsRefused) {
  std::vector<TruthProfileSample> samples = StillProfile(11, 0.01);
  // 0 -> 100 m/s between samples 5 and 6 (0.01 s): the spline's slope is ~1e4 m/s^2.
  for (size_t i = 6; i < samples.size(); ++i) samples[i].v_eb_n = Vector3d(100.0, 0.0, 0.0);
  ExpectContains(RejectionOf(TruthProfileMotion(samples), 100.0),
                 {"truth_profile[", "accelerates at", "at most 1000 m/s^2"});
}

// A truth profile sampled at 1 Hz from a generated drive (accelerate, turn, climb) is accepted: its
// positions agree with its velocities' integral to the spline error, far inside 10 m + 10 %. The
// same profile with one row's latitude off by 10 deg (1,100 km) is refused naming that row.
TEST(PlannedMotionLimits, TruthProfilePositionsMustAgreeWithItsVelocities) {
  MotionSpec drive = Moving(0.0);
  drive.initial.llh.lat_rad = 45.0 * kDeg;
  AccelerateSegment acc;
  acc.acceleration_m_per_s2 = 2.0;
  acc.target_speed_m_per_s = 20.0;
  drive.segments = {StaticSegment{5.0}, acc, testing::TurnByRate(10.0, 90.0, 2.0),
                    ConstantVelocitySegment{30.0}};
  const Trajectory truth = GenerateTrajectory(drive, 100.0);
  std::vector<TruthProfileSample> samples;
  for (size_t k = 0; k < truth.truth.size(); k += 100) {
    TruthProfileSample s;
    s.t_s = truth.truth[k].t_s;
    s.llh = truth.truth[k].llh;
    s.v_eb_n = truth.truth[k].v_eb_n;
    s.attitude = truth.truth[k].euler();
    samples.push_back(s);
  }
  ASSERT_GT(samples.size(), 40u);
  EXPECT_NO_THROW(TrajectoryGenerator(TruthProfileMotion(samples), 100.0));
  samples[30].llh.lat_rad += 10.0 * kDeg;
  ExpectContains(RejectionOf(TruthProfileMotion(samples), 100.0),
                 {"truth_profile[30]", "disagree by", "10 m + 10 %"});
}

}  // namespace
}  // namespace driftlab
