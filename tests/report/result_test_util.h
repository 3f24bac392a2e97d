// Shared by the result file, gate and HTML report tests (result_file_test.cc, result_gate_test.cc,
// result_report_test.cc): a synthetic JobResult with known statistics, reading a file whole, and
// a temporary directory per test.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "driftlab/app/result_file.h"
#include "support/spec_errors.h"

namespace driftlab::app::result_test {

namespace fs = std::filesystem;

// A synthetic result with known statistics: N runs, epochs every 60 s to 600 s, checkpoints at
// 300 s and 600 s. Component c's statistics at time t are (c + 1) * (t / 600) times fixed base
// values, all multiplied by `scale`; per-run values are scale * (c + 1) * (t / 600) * w_r with
// w_r = sin(2.4 r) (bounded, deterministic). The percentiles are those of the stored per-run
// values (nearest rank), so the message is self-consistent and valid.
inline v1::JobResult MakeResult(double scale, int runs = 50,
                                const std::string& name = "synthetic") {
  v1::JobResult result;
  result.mutable_job()->set_name(name);
  result.mutable_job()->set_description("built by result_test_util.h");
  result.mutable_job()->set_rate_hz(100);
  result.set_engine_version("test");
  result.set_seed(42);
  result.set_runs(runs);
  result.set_first_run(0);
  result.set_run_count(runs);
  for (int i = 0; i <= 10; ++i) {
    const double t = 60.0 * i;
    v1::EpochStatistics* epoch = result.add_epochs();
    epoch->set_t_s(t);
    for (int c = 0; c < kErrorComponentCount; ++c) {
      const double k = scale * (c + 1) * t / 600.0;
      v1::ComponentStatistics* s = epoch->add_components();
      s->set_component(static_cast<v1::ErrorComponent>(c + 1));
      s->set_mean(c < 9 ? -0.1 * k : 1.1 * k);  // signed components may have a negative bias
      s->set_std(k);
      s->set_rms(1.005 * k);
      s->set_std_ci95_low(0.8 * k);
      s->set_std_ci95_high(1.25 * k);
      s->set_rms_ci95_low(0.81 * k);
      s->set_rms_ci95_high(1.26 * k);
    }
  }
  for (const double t : {300.0, 600.0}) {
    v1::Checkpoint* checkpoint = result.add_checkpoints();
    checkpoint->set_t_s(t);
    std::vector<std::vector<double>> abs_values(kErrorComponentCount);
    for (int r = 0; r < runs; ++r) {
      v1::RunValues* run = checkpoint->add_runs();
      run->set_run_index(r);
      const double w = std::sin(2.4 * r);
      for (int c = 0; c < kErrorComponentCount; ++c) {
        const double k = scale * (c + 1) * t / 600.0;
        const double value = c < 9 ? k * w : k * std::abs(w);
        run->add_values(value);
        abs_values[c].push_back(std::abs(value));
      }
    }
    for (int c = 0; c < kErrorComponentCount; ++c) {
      std::vector<double>& a = abs_values[c];
      std::sort(a.begin(), a.end());
      const auto rank = [&](double p) { return a[static_cast<size_t>(std::ceil(p * runs)) - 1]; };
      v1::ComponentPercentiles* p = checkpoint->add_components();
      p->set_component(static_cast<v1::ErrorComponent>(c + 1));
      p->set_p50(rank(0.50));
      p->set_p68(rank(0.68));
      p->set_p95(rank(0.95));
      p->set_p99(rank(0.99));
      p->set_max_abs(a.back());
    }
    checkpoint->set_cep50_m(checkpoint->components(9).p50());
    checkpoint->set_cep95_m(checkpoint->components(9).p95());
    checkpoint->set_drms2_m(2.0 * scale * 10 * t / 600.0);
  }
  v1::Timings* timings = result.mutable_timings();
  timings->set_wall_s(1.5);
  timings->set_cpu_s(2.9);
  timings->set_samples(uint64_t{60001} * runs);
  timings->set_samples_per_s(60001.0 * runs / 1.5);
  timings->set_threads(2);
  return result;
}

inline std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("driftlab_rg_lib_" + std::to_string(getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  ~TempDir() { fs::remove_all(dir_); }
  fs::path operator/(const std::string& name) const { return dir_ / name; }

 private:
  fs::path dir_;
};

using testing::ErrorOf;

}  // namespace driftlab::app::result_test
