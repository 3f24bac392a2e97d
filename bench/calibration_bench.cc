// Fit times: the multi-position IMU calibration of a 30-minute 100 Hz tumble and the Allan
// noise-model fit of a 10-hour 100 Hz static recording, both through the library cores behind the
// CLI and the gRPC service (app/calibration_job.h).
//
//   BM_CalibrateTumble30Min/0: RunCalibration("imu") on the table in memory (static detection,
//     accelerometer fit, gyro fit with its sample-by-sample attitude integration, covariances).
//   BM_CalibrateTumble30Min/1: the same plus ReadNumericCsv of the CSV (%.17g), i.e. what
//     `driftlab calibrate imu tumble.csv` does before writing its output.
//   BM_NoiseFitTenHours: RunNoiseFit on 6 columns x 3.6e6 samples (overlapping ADEV of each
//     column on the octave grid, per-axis and per-triad Ceres fits, model and curves).
// Data: the tactical preset through the engine's ImuErrorSimulator (seeded); the tumble without
// in-run bias variation (as the calibration tests), 60 poses: 30 s initial, then 59 x (1 s
// rotation + 29 s pose) = 1800 s, 180000 samples.
// Run: build-rel/bench/driftlab_bench_calibration --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true   (the medians are the numbers to quote)
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "driftlab/app/calibration_job.h"
#include "driftlab/calib/tumble.h"
#include "driftlab/presets.h"
#include "driftlab/sensors.h"

namespace driftlab {
namespace {

calib::TumbleSpec ThirtyMinuteSpec() {
  calib::TumbleSpec spec;
  spec.rate_hz = 100.0;
  spec.initial_static_s = 30.0;
  spec.pose_s = 29.0;
  spec.rotation_s = 1.0;
  spec.pose_count = 60;
  spec.earth_rate = false;
  return spec;
}

const app::NumericTable& TumbleTable() {
  static const app::NumericTable table = [] {
    ImuErrorModel model = FindImuPreset("tactical");
    model.gyro_g_sensitivity.setZero();
    for (TriadErrorParams* t : {&model.gyro, &model.accel}) {
      t->bias_flicker.bias_instability = 0.0;
      t->bias_gauss_markov = {};
      t->random_walk = 0.0;
    }
    const calib::Tumble tumble = calib::SimulateTumble(ThirtyMinuteSpec(), model, 5, 0);
    app::NumericTable t;
    t.columns = {"t_s", "gx", "gy", "gz", "ax", "ay", "az"};
    const calib::RawImuRecording& r = tumble.recording;
    t.values.reserve(7 * r.size());
    for (size_t k = 0; k < r.size(); ++k) {
      t.values.push_back(r.t_s[k]);
      for (int i = 0; i < 3; ++i) t.values.push_back(r.omega_ib_s[k][i]);
      for (int i = 0; i < 3; ++i) t.values.push_back(r.f_ib_s[k][i]);
    }
    return t;
  }();
  return table;
}

std::string TumbleCsv() {
  static const std::string path = [] {
    const std::string p =
        (std::filesystem::temp_directory_path() / "driftlab_bench_tumble_30min.csv").string();
    const app::NumericTable& t = TumbleTable();
    std::FILE* f = std::fopen(p.c_str(), "w");
    std::fputs("t_s,gx,gy,gz,ax,ay,az\n", f);
    for (size_t k = 0; k < t.rows(); ++k) {
      const double* v = &t.values[7 * k];
      std::fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", v[0], v[1], v[2], v[3], v[4],
                   v[5], v[6]);
    }
    std::fclose(f);
    return p;
  }();
  return path;
}

void BM_CalibrateTumble30Min(benchmark::State& state) {
  app::CalibrateSettings settings;
  settings.kind = "imu";
  settings.lat_deg = 45.0;  // TumbleSpec default latitude
  const bool from_csv = state.range(0) == 1;
  const std::string csv = from_csv ? TumbleCsv() : "";
  const app::NumericTable& table = TumbleTable();
  int poses = 0;
  for (auto _ : state) {
    const v1::CalibrationResult result =
        app::RunCalibration(settings, from_csv ? app::ReadNumericCsv(csv) : table);
    poses = result.fits(0).poses_used();
    benchmark::DoNotOptimize(result.fits(1).residual_rms());
  }
  state.counters["poses"] = poses;
  state.counters["samples"] = static_cast<double>(table.rows());
}
BENCHMARK(BM_CalibrateTumble30Min)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_NoiseFitTenHours(benchmark::State& state) {
  static const app::NumericTable table = [] {
    constexpr double kRateHz = 100.0;
    constexpr int64_t kSamples = 10 * 3600 * 100;
    app::NumericTable t;
    t.columns = {"omega_x_rad_per_s", "omega_y_rad_per_s", "omega_z_rad_per_s",
                 "f_x_m_per_s2",      "f_y_m_per_s2",      "f_z_m_per_s2"};
    t.values.resize(6 * static_cast<size_t>(kSamples));
    ImuErrorSimulator sim(FindImuPreset("tactical"), 2024, 0, kRateHz);
    ImuSample ideal, measured;
    for (int64_t i = 0; i < kSamples; ++i) {
      sim.Apply(ideal, &measured);
      for (int a = 0; a < 3; ++a) {
        t.values[6 * i + a] = measured.omega_ib_b[a];
        t.values[6 * i + 3 + a] = measured.f_ib_b[a];
      }
    }
    return t;
  }();
  app::NoiseFitSettings settings;
  settings.rate_hz = 100.0;
  double fit_time_s = 0.0;
  for (auto _ : state) {
    const v1::NoiseModelFit fit = app::RunNoiseFit(settings, table);
    fit_time_s = fit.fit_time_s();
    benchmark::DoNotOptimize(fit.terms_size());
  }
  state.counters["samples_per_column"] = static_cast<double>(table.rows());
  state.counters["fit_time_s"] = fit_time_s;
}
BENCHMARK(BM_NoiseFitTenHours)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
