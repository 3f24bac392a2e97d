// Throughput of the engine stages in IMU samples per second per core: the trajectory generator
// (truth + ideal increments), mechanization A (NED, WGS-84, coning/sculling) and mechanization B
// (seed 000, flat frame). Motion: a 100 Hz town drive with stops and turns
// (examples/car_drive.json).
#include <benchmark/benchmark.h>

#include <cmath>

#include "driftlab/ins.h"
#include "driftlab/trajectory.h"

namespace driftlab {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kRate_hz = 100.0;

MotionSpec CarDrive(EarthModel earth_model) {
  MotionSpec m;
  m.earth_model = earth_model;
  m.initial.llh = {48.1374 * kDeg, 11.5755 * kDeg, 520.0};
  m.initial.attitude.yaw_rad = 90.0 * kDeg;
  auto accelerate = [](double speed, double accel) {
    AccelerateSegment a;
    a.acceleration_m_per_s2 = accel;
    a.target_speed_m_per_s = speed;
    return a;
  };
  auto turn = [](double radius, bool right) {
    TurnSegment t;
    t.radius_m = radius;
    t.right = right;
    t.angle_rad = 90.0 * kDeg;
    t.transition_s = 2.0;
    return t;
  };
  m.segments = {
      StaticSegment{100.0},           accelerate(14.0, 2.0), ConstantVelocitySegment{60.0},
      accelerate(6.0, 2.5),           turn(15.0, true),      accelerate(14.0, 1.5),
      ConstantVelocitySegment{90.0},  accelerate(0.0, 2.5),  StaticSegment{25.0},
      accelerate(8.0, 2.0),           turn(12.0, false),     accelerate(16.0, 1.5),
      ConstantVelocitySegment{120.0}, accelerate(0.0, 2.0),  StaticSegment{30.0}};
  return m;
}

const Trajectory& CarTrajectory(EarthModel earth_model) {
  static const Trajectory wgs84 = GenerateTrajectory(CarDrive(EarthModel::kWgs84), kRate_hz);
  static const Trajectory flat = GenerateTrajectory(CarDrive(EarthModel::kFlat), kRate_hz);
  return earth_model == EarthModel::kWgs84 ? wgs84 : flat;
}

void BM_Generator(benchmark::State& state) {
  const MotionSpec motion = CarDrive(EarthModel::kWgs84);
  int64_t samples = 0;
  for (auto _ : state) {
    TrajectoryGenerator generator(motion, kRate_hz);
    TrajectorySample sample;
    while (generator.Next(&sample)) benchmark::DoNotOptimize(sample);
    samples += generator.step();
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_Generator)->Unit(benchmark::kMillisecond);

// The same without the point samples (what the free-inertial NED runs' shared truth computes).
void BM_GeneratorIncrementsOnly(benchmark::State& state) {
  const MotionSpec motion = CarDrive(EarthModel::kWgs84);
  int64_t samples = 0;
  for (auto _ : state) {
    TrajectoryGenerator generator(motion, kRate_hz);
    generator.set_point_samples(false);
    TrajectorySample sample;
    while (generator.Next(&sample)) benchmark::DoNotOptimize(sample);
    samples += generator.step();
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_GeneratorIncrementsOnly)->Unit(benchmark::kMillisecond);

void BM_MechanizationA(benchmark::State& state) {
  const Trajectory& trajectory = CarTrajectory(EarthModel::kWgs84);
  NedMechanizationOptions options;
  options.vertical = VerticalChannel::kFree;
  int64_t samples = 0;
  for (auto _ : state) {
    NedMechanization ins(trajectory.environment, trajectory.truth.front(), trajectory.dt_s,
                         options);
    for (const ImuIncrement& increment : trajectory.increments) ins.Update(increment);
    benchmark::DoNotOptimize(ins.state());
    samples += static_cast<int64_t>(trajectory.increments.size());
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_MechanizationA)->Unit(benchmark::kMillisecond);

void BM_MechanizationB(benchmark::State& state) {
  const Trajectory& trajectory = CarTrajectory(EarthModel::kFlat);
  Seed000Options options;
  options.static_period_s = 90.0;
  int64_t samples = 0;
  for (auto _ : state) {
    Seed000Mechanization ins(trajectory.dt_s, options);
    for (const ImuSample& sample : trajectory.samples) ins.Update(sample);
    benchmark::DoNotOptimize(ins.r_nav_m());
    samples += static_cast<int64_t>(trajectory.samples.size());
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_MechanizationB)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
