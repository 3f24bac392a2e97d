// Cost of the random streams and of the IMU error model per sample (DESIGN.md "Speed by design").
// Build Release (build-*-rel) for numbers; items_per_second = Gaussian deviates or IMU samples
// (gyro + accel triads) per second on one core.
#include <benchmark/benchmark.h>

#include <vector>

#include "driftlab/random.h"
#include "driftlab/sensors.h"

namespace driftlab {
namespace {

// Block fill of N(0, 1) deviates (Philox4x32-10 + Box-Muller with own ln/sin/cos).
void BM_FillGaussian(benchmark::State& state) {
  const RandomStream stream(1, 0, {SensorId::kGyro, 0, ErrorTerm::kWhiteNoise, 0});
  std::vector<double> out(static_cast<size_t>(state.range(0)));
  uint64_t index = 0;
  for (auto _ : state) {
    stream.FillGaussian(index, out);
    index += out.size();
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_FillGaussian)->Arg(64)->Arg(1024);

// Raw Philox blocks (4 x 32 bits each).
void BM_Philox4x32(benchmark::State& state) {
  std::array<uint32_t, 4> counter{0, 0, 7, 9};
  uint32_t sink = 0;
  for (auto _ : state) {
    const auto out = Philox4x32(counter, {0x12345678u, 0x9abcdef0u});
    sink ^= out[0] ^ out[3];
    ++counter[0];
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Philox4x32);

ImuErrorModel AllTermsOn() {
  ImuErrorModel m;
  for (TriadErrorParams* t : {&m.gyro, &m.accel}) {
    t->fixed_bias = Eigen::Vector3d(1e-4, -2e-4, 3e-4);
    t->turn_on_bias_sigma = 5e-5;
    t->bias_gauss_markov = {2e-5, 100.0};
    t->bias_flicker = {1e-5, 1.0, 1000.0};
    t->white_noise_density = 1e-4;
    t->random_walk = 1e-6;
    t->scale_factor_fixed = Eigen::Vector3d(1e-4, 2e-4, -3e-4);
    t->scale_factor_sigma = 1e-4;
    t->scale_factor_asymmetry = Eigen::Vector3d(1e-5, 0, -1e-5);
    t->misalignment_sigma_rad = 1e-4;
    t->quantization = 1e-7;
    t->range = 10.0;
  }
  m.gyro_g_sensitivity = Eigen::Matrix3d::Identity() * 1e-5;
  return m;
}

ImuErrorModel WhiteNoiseOnly() {
  ImuErrorModel m;
  m.gyro.white_noise_density = 1e-4;
  m.accel.white_noise_density = 1e-3;
  return m;
}

// One IMU sample (gyro and accel increments) with the given model; arg = rate in Hz.
template <ImuErrorModel (*kModel)()>
void BM_ImuErrorIncrement(benchmark::State& state) {
  ImuErrorSimulator sim(kModel(), 42, 0, static_cast<double>(state.range(0)));
  ImuIncrement ideal, measured;
  ideal.delta_theta_ib_b = Eigen::Vector3d(1e-3, 2e-3, 3e-3);
  ideal.delta_v_ib_b = Eigen::Vector3d(0.0, 0.0, -0.098);
  for (auto _ : state) {
    sim.Apply(ideal, &measured);
    benchmark::DoNotOptimize(measured);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ImuErrorIncrement<AllTermsOn>)->Arg(100)->Arg(1000);
BENCHMARK(BM_ImuErrorIncrement<WhiteNoiseOnly>)->Arg(100)->Arg(1000);

void BM_ImuErrorSampleAllTerms(benchmark::State& state) {
  ImuErrorSimulator sim(AllTermsOn(), 42, 0, static_cast<double>(state.range(0)));
  ImuSample ideal, measured;
  ideal.omega_ib_b = Eigen::Vector3d(0.1, 0.2, 0.3);
  ideal.f_ib_b = Eigen::Vector3d(0.0, 0.0, -9.8);
  for (auto _ : state) {
    sim.Apply(ideal, &measured);
    benchmark::DoNotOptimize(measured);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ImuErrorSampleAllTerms)->Arg(100)->Arg(1000);

// Per-run construction (validation, flicker design, per-run constants, channel buffers).
void BM_ImuErrorSimulatorConstruction(benchmark::State& state) {
  const ImuErrorModel model = AllTermsOn();
  uint32_t run = 0;
  for (auto _ : state) {
    ImuErrorSimulator sim(model, 42, run++, 1000.0);
    benchmark::DoNotOptimize(&sim);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ImuErrorSimulatorConstruction);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
