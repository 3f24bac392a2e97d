// Cost per IMU sample of the attitude and navigation filters: the complementary attitude filter,
// the 15-state covariance propagation (per propagation step and per IMU sample at a given step),
// and the INS/GNSS error-state filter (mechanization + covariance every 10 samples + a 6-D GNSS
// update every 100 samples).
// Build Release for numbers; items_per_second = IMU samples per second on one core.
#include <benchmark/benchmark.h>

#include <vector>

#include "driftlab/complementary_filter.h"
#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/gnss.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/presets.h"
#include "driftlab/sensors.h"
#include "driftlab/trajectory.h"

namespace driftlab {
namespace {

constexpr double kDeg = M_PI / 180.0;

// 60 s car-like drive at 100 Hz (accelerate, turn, straight), generated once.
const Trajectory& Drive() {
  static const Trajectory t = [] {
    MotionSpec m;
    m.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
    AccelerateSegment a;
    a.acceleration_m_per_s2 = 2.0;
    a.target_speed_m_per_s = 15.0;
    m.segments.push_back(a);
    TurnSegment turn;
    turn.rate_rad_per_s = 10.0 * kDeg;
    turn.angle_rad = 180.0 * kDeg;
    turn.transition_s = 2.0;
    m.segments.push_back(turn);
    m.segments.push_back(ConstantVelocitySegment{30.0});
    return GenerateTrajectory(m, 100.0);
  }();
  return t;
}

void BM_ComplementaryFilter(benchmark::State& state) {
  const Trajectory& t = Drive();
  ComplementaryFilterOptions o;
  o.kind = static_cast<ComplementaryPairKind>(state.range(0));
  o.crossover_hz = 0.05;
  int64_t samples = 0;
  for (auto _ : state) {
    ComplementaryAttitudeFilter f(o, 100.0);
    for (const ImuSample& s : t.samples) f.Update(s);
    benchmark::DoNotOptimize(f.attitude());
    samples += static_cast<int64_t>(t.samples.size());
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_ComplementaryFilter)
    ->Arg(static_cast<int>(ComplementaryPairKind::kFirstOrder))
    ->Arg(static_cast<int>(ComplementaryPairKind::kButterworth4))
    ->Arg(static_cast<int>(ComplementaryPairKind::kButterworth4Seed));

// The tactical preset: augmented = 0 reduced to the 15 core states (no flicker, scale factor,
// misalignment), 1 the whole preset (87 states: flicker as 9 Gauss-Markov states per axis, scale
// factor and misalignment augmented).
ImuErrorModel TacticalModel(int64_t augmented) {
  ImuErrorModel model = FindImuPreset("tactical");
  if (augmented == 0) {
    for (TriadErrorParams* p : {&model.gyro, &model.accel}) {
      p->bias_flicker = {};
      p->scale_factor_sigma = 0.0;
      p->misalignment_sigma_rad = 0.0;
    }
  }
  return model;
}

ErrorStateMatrix SmallIdentity(const ErrorStateNoise& noise) {
  const int n = ErrorStateLayout(noise).size;
  return ErrorStateMatrix::Identity(n, n) * 1e-4;
}

// One covariance propagation step (F, discretisation, P update); arg 0: 0 = Van Loan, 1 = 2nd
// order (structured); arg 1: 0 = 15 states, 1 = augmented.
void BM_CovariancePropagationStep(benchmark::State& state) {
  const Trajectory& t = Drive();
  const ErrorStateNoise noise = MakeErrorStateNoise(TacticalModel(state.range(1))).noise;
  ErrorCovariancePropagator p(
      t.environment, noise, SmallIdentity(noise),
      state.range(0) == 0 ? Discretization::kVanLoan : Discretization::kSecondOrder);
  size_t k = 0;
  for (auto _ : state) {
    p.Propagate(t.truth[k], t.samples[k].f_ib_b, 0.1, t.samples[k].omega_ib_b);
    k = (k + 1) % t.samples.size();
    benchmark::DoNotOptimize(p.P().data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CovariancePropagationStep)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1});

// Linear covariance analysis along the drive, per IMU sample, for step_samples = range(0); range(1)
// 0 = 15 states, 1 = augmented.
void BM_FreeInertialCovariancePerSample(benchmark::State& state) {
  const Trajectory& t = Drive();
  const ErrorStateNoise noise = MakeErrorStateNoise(TacticalModel(state.range(1))).noise;
  CovarianceAnalysisOptions o;
  o.step_samples = state.range(0);
  o.epoch_every_samples = 100 * o.step_samples;
  o.discretization = Discretization::kSecondOrder;
  int64_t samples = 0;
  for (auto _ : state) {
    auto out = FreeInertialCovariance(t, noise, SmallIdentity(noise), o);
    benchmark::DoNotOptimize(out.data());
    samples += static_cast<int64_t>(t.increments.size());
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_FreeInertialCovariancePerSample)->Args({1, 0})->Args({10, 0})->Args({10, 1});

// INS/GNSS filter per IMU sample: measured increments precomputed (sensor model not timed);
// arg 0 = 15 states, 1 = augmented.
void BM_InsGnssFilterPerSample(benchmark::State& state) {
  const Trajectory& t = Drive();
  const ImuErrorModel model = TacticalModel(state.range(0));
  ImuErrorSimulator imu(model, 1, 0, 100.0);
  std::vector<ImuIncrement> measured(t.increments.size());
  for (size_t k = 0; k < measured.size(); ++k) imu.Apply(t.increments[k], &measured[k]);
  GnssConfig gnss;
  GnssSimulator receiver(gnss, t.environment, 100.0, 1, 0);
  std::vector<GnssMeasurement> fixes(measured.size() + 1);
  std::vector<char> has_fix(measured.size() + 1, 0);
  for (size_t k = 1; k <= measured.size(); ++k) {
    has_fix[k] = receiver.Measure(static_cast<int64_t>(k), t.truth[k], Vector3d::Zero(), &fixes[k]);
  }
  InsGnssFilterOptions o;
  o.imu_noise = MakeErrorStateNoise(model).noise;
  o.gnss = gnss;
  o.propagation_step_samples = 10;
  const ErrorStateMatrix P0 =
      InitialErrorCovariance(Vector3d(3, 3, 5), Vector3d(0.1, 0.1, 0.1), Vector3d(1e-3, 1e-3, 5e-3),
                             t.truth[0].euler(), o.imu_noise);
  int64_t samples = 0;
  for (auto _ : state) {
    InsGnssFilter f(t.environment, t.truth[0], P0, 100.0, o);
    for (size_t k = 1; k <= measured.size(); ++k) {
      f.Predict(measured[k - 1]);
      if (has_fix[k]) f.Update(fixes[k], measured[k - 1].delta_theta_ib_b * 100.0);
    }
    benchmark::DoNotOptimize(f.state());
    samples += static_cast<int64_t>(measured.size());
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_InsGnssFilterPerSample)->Arg(0)->Arg(1);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
