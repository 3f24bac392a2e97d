// Datasets service over gRPC (in-process server on 127.0.0.1:0): ExportRun streams the IMU data
// `driftlab export` writes for the same seed and run, and the engine's own navigation solution of
// that Monte-Carlo run; ScoreSolution of that solution reproduces the run's in-process error
// statistics (RunMonteCarlo on the shard holding only that run).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/app/translate.h"
#include "driftlab/io.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/server/data_services.h"
#include "in_process_server.h"

namespace driftlab {
namespace {

using testing::InProcessServer;
using testing::TestAuthenticator;

// 5 s at rest, accelerate to 10 m/s, a 90 deg turn, 10 s straight (about 30 s at 100 Hz), the
// tactical preset, initial errors in every axis, epochs every 0.5 s and a checkpoint at 7.3 s.
constexpr char kJobJson[] = R"({
  "name": "datasets_test",
  "motion": {
    "earth_model": "WGS84",
    "initial": {"lat_deg": 45.0, "lon_deg": 7.0, "height_m": 300.0, "yaw_deg": 30.0},
    "segments": [
      {"static": {"duration_s": 5}},
      {"accelerate": {"acceleration_m_per_s2": 1.0, "target_speed_m_per_s": 10.0}},
      {"turn": {"radius_m": 50, "direction": "LEFT", "angle_deg": 90, "transition_s": 2}},
      {"constant_velocity": {"duration_s": 10}}
    ]
  },
  "rate_hz": 100,
  "navigation": {"mechanization": "NED"},
  "sensor": {"preset": "tactical"},
  "monte_carlo": {
    "runs": 5,
    "seed": 3,
    "initial_errors": {
      "position_ned_m": [1.0, 1.0, 2.0],
      "velocity_ned_m_per_s": [0.05, 0.05, 0.05],
      "attitude_deg": [0.05, 0.05, 0.2]
    },
    "epoch_interval_s": 0.5,
    "checkpoint_times_s": [7.3]
  }
})";

struct Export {
  v1::ExportHeader header;
  std::vector<double> imu, truth, navigation;
};

class DatasetsServiceTest : public ::testing::Test {
 protected:
  grpc::Status ExportRun(const v1::RunRef& run, bool navigation, uint32_t rows_per_chunk,
                         Export* out) {
    v1::ExportRunRequest request;
    *request.mutable_run() = run;
    request.set_include_navigation(navigation);
    request.set_rows_per_chunk(rows_per_chunk);
    grpc::ClientContext context;
    auto reader = stub_->ExportRun(&context, request);
    v1::ExportRunResponse response;
    bool first = true;
    while (reader->Read(&response)) {
      EXPECT_EQ(response.has_header(), first) << "the header comes first, exactly once";
      first = false;
      if (response.has_header()) {
        out->header = response.header();
        continue;
      }
      const v1::ExportChunk& c = response.chunk();
      out->imu.insert(out->imu.end(), c.imu().begin(), c.imu().end());
      out->truth.insert(out->truth.end(), c.truth().begin(), c.truth().end());
      out->navigation.insert(out->navigation.end(), c.navigation().begin(), c.navigation().end());
    }
    return reader->Finish();
  }

  // Scores `rows` (row-major, `columns`) in messages of `rows_per_message` rows.
  grpc::Status Score(const v1::RunRef& run, const std::vector<std::string>& columns,
                     const std::vector<double>& rows, size_t rows_per_message,
                     v1::JobResult* result) {
    grpc::ClientContext context;
    auto writer = stub_->ScoreSolution(&context, result);
    v1::ScoreSolutionRequest header;
    *header.mutable_header()->mutable_run() = run;
    for (const std::string& c : columns) header.mutable_header()->add_columns(c);
    writer->Write(header);
    const size_t step = rows_per_message * columns.size();
    for (size_t begin = 0; begin < rows.size(); begin += step) {
      v1::ScoreSolutionRequest r;
      const size_t end = std::min(rows.size(), begin + step);
      r.mutable_rows()->mutable_values()->Add(rows.begin() + static_cast<ptrdiff_t>(begin),
                                              rows.begin() + static_cast<ptrdiff_t>(end));
      if (!writer->Write(r)) break;
    }
    writer->WritesDone();
    return writer->Finish();
  }

  TestAuthenticator accept_{true};
  server::ServerLimits limits_;
  std::unique_ptr<v1::Datasets::Service> service_ = server::MakeDatasetsService(&accept_, limits_);
  InProcessServer server_{{service_.get()}};
  std::unique_ptr<v1::Datasets::Stub> stub_ = v1::Datasets::NewStub(server_.channel());
};

v1::RunRef MakeRun(const v1::Job& job, uint64_t seed, uint32_t run_index) {
  v1::RunRef run;
  *run.mutable_job() = job;
  run.set_seed(seed);
  run.set_run_index(run_index);
  return run;
}

// Reads a CSV written by the engine's writers: header names and the numbers (strtod reads back
// the shortest round-trip text exactly).
std::vector<double> ReadCsv(const std::filesystem::path& path, std::string* header) {
  std::ifstream in(path);
  std::getline(in, *header);
  std::vector<double> values;
  std::string line;
  while (std::getline(in, line)) {
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) values.push_back(std::strtod(field.c_str(), nullptr));
  }
  return values;
}

std::string Join(const google::protobuf::RepeatedPtrField<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

TEST_F(DatasetsServiceTest, ExportedImuAndTruthRowsEqualTheDriftlabExportCsv) {
  const v1::Job job = app::ParseJobJson(kJobJson);
  constexpr uint64_t kSeed = 9;
  constexpr uint32_t kRun = 2;
  Export got;
  const grpc::Status status = ExportRun(MakeRun(job, kSeed, kRun), false, 1000, &got);
  ASSERT_TRUE(status.ok()) << status.error_message();

  // What `driftlab export --seed 9 --run 2` writes (clients/cli/export_command.cc), in-process.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("datasets_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    const SimulationSpec spec = app::ValidateJob(app::JobFile{job, ""}).spec.simulation;
    const SensorRun sensor{*app::ToImuErrorModel(job), kSeed, kRun};
    TruthCsvWriter truth(dir / "truth.csv");
    ImuCsvWriter imu(dir / "imu.csv");
    RunSimulation(spec, &sensor, [&](const SimulationStep& step) {
      truth.Write(*step.truth);
      imu.Write(step.truth->t_s, *step.measured_increment, *step.measured_sample);
    });
    truth.Close();
    imu.Close();
  }
  std::string imu_header, truth_header;
  const std::vector<double> imu_csv = ReadCsv(dir / "imu.csv", &imu_header);
  const std::vector<double> truth_csv = ReadCsv(dir / "truth.csv", &truth_header);
  std::filesystem::remove_all(dir);

  EXPECT_EQ(Join(got.header.imu_columns()), imu_header);
  EXPECT_EQ(Join(got.header.truth_columns()), truth_header);
  EXPECT_EQ(got.header.rate_hz(), 100.0);
  EXPECT_EQ(got.header.imu_rows() * 13, imu_csv.size());
  EXPECT_EQ(got.header.truth_rows() * 10, truth_csv.size());
  EXPECT_EQ(got.header.navigation_rows(), 0u);
  EXPECT_TRUE(got.navigation.empty());
  // Exact: the same doubles (the CSV text round-trips exactly).
  ASSERT_EQ(got.imu.size(), imu_csv.size());
  ASSERT_EQ(got.truth.size(), truth_csv.size());
  size_t imu_mismatches = 0, truth_mismatches = 0;
  for (size_t i = 0; i < imu_csv.size(); ++i) imu_mismatches += got.imu[i] != imu_csv[i];
  for (size_t i = 0; i < truth_csv.size(); ++i) truth_mismatches += got.truth[i] != truth_csv[i];
  EXPECT_EQ(imu_mismatches, 0u);
  EXPECT_EQ(truth_mismatches, 0u);
  // The data carry sensor errors: run 2 differs from run 3 (independent streams).
  Export other;
  ASSERT_TRUE(ExportRun(MakeRun(job, kSeed, 3), false, 0, &other).ok());
  EXPECT_NE(other.imu, got.imu);
  EXPECT_EQ(other.truth, got.truth);
}

// Export with navigation, score that navigation, compare with RunMonteCarlo of the one-run shard.
class DatasetsRoundTrip : public DatasetsServiceTest {
 protected:
  void Check(const v1::Job& job, uint64_t seed, uint32_t run_index) {
    const v1::RunRef run = MakeRun(job, seed, run_index);
    Export exported;
    const grpc::Status export_status = ExportRun(run, true, 0, &exported);
    ASSERT_TRUE(export_status.ok()) << export_status.error_message();
    ASSERT_EQ(exported.navigation.size(), exported.header.navigation_rows() * 10);
    ASSERT_GT(exported.header.navigation_rows(), 0u);

    // Send the columns in reverse order (any order is allowed).
    std::vector<std::string> columns(exported.header.navigation_columns().rbegin(),
                                     exported.header.navigation_columns().rend());
    std::vector<double> rows;
    for (size_t r = 0; r < exported.header.navigation_rows(); ++r) {
      for (int c = 9; c >= 0; --c) rows.push_back(exported.navigation[r * 10 + c]);
    }
    v1::JobResult scored;
    const grpc::Status score_status = Score(run, columns, rows, 777, &scored);
    ASSERT_TRUE(score_status.ok()) << score_status.error_message();

    // The in-process reference: `driftlab run --seed S` restricted to the shard [run, run + 1).
    app::MonteCarloOverrides overrides;
    overrides.seed = seed;
    MonteCarloSpec spec = app::ToMonteCarloSpec(app::JobFile{job, ""}, overrides);
    spec.first_run = run_index;
    spec.run_count = 1;
    const v1::JobResult reference =
        app::ToJobResult(app::JobAsRun(job, spec), RunMonteCarlo(spec), DRIFTLAB_VERSION);

    EXPECT_EQ(scored.job().SerializeAsString(), reference.job().SerializeAsString());
    EXPECT_EQ(scored.seed(), reference.seed());
    EXPECT_EQ(scored.runs(), reference.runs());
    EXPECT_EQ(scored.first_run(), run_index);
    EXPECT_EQ(scored.run_count(), 1u);
    ASSERT_EQ(scored.epochs_size(), reference.epochs_size());
    ASSERT_EQ(scored.checkpoints_size(), reference.checkpoints_size());

    const MonteCarloStatisticsData got = app::StatisticsFromJobResult(scored, "scored").data();
    const MonteCarloStatisticsData want =
        app::StatisticsFromJobResult(reference, "reference").data();
    EXPECT_EQ(got.epoch_times_s, want.epoch_times_s);
    EXPECT_EQ(got.runs, want.runs);
    // The navigation rows carry angles in degrees (the API's edge unit): rad -> deg -> rad changes
    // latitude, longitude and the Euler angles by at most 1 ulp each, so
    //  * north/east position error by <= (R + h) ulp(pi) = 6.4e6 m x 4.4e-16 = 2.8e-9 m (1e-8 m);
    //  * roll/pitch/yaw errors by <= 2 ulp(pi) = 8.9e-16 rad (2e-15 rad);
    //  * down position (height in m) and the velocities pass unconverted: bit-identical.
    const double tolerance[kNumErrorComponents] = {1e-8,  1e-8,  0.0,   0.0,  0.0, 0.0,
                                                   2e-15, 2e-15, 2e-15, 1e-8, 1e-8};
    size_t compared = 0;
    double max_position_diff_m = 0.0, max_angle_diff_rad = 0.0;
    for (size_t e = 0; e < want.epochs.size(); ++e) {
      for (int c = 0; c < kNumErrorComponents; ++c) {
        const long double g = got.epochs[e].sum[c].Value(), w = want.epochs[e].sum[c].Value();
        const double diff = std::abs(static_cast<double>(g - w));
        double& max_diff = (c >= 6 && c <= 8) ? max_angle_diff_rad : max_position_diff_m;
        max_diff = std::max(max_diff, diff);
        if (tolerance[c] == 0.0) {
          EXPECT_TRUE(got.epochs[e].sum[c] == want.epochs[e].sum[c])
              << "epoch " << e << " component " << c << ": " << static_cast<double>(g) << " vs "
              << static_cast<double>(w);
        } else {
          EXPECT_NEAR(static_cast<double>(g), static_cast<double>(w), tolerance[c])
              << "epoch " << e << " component " << c;
        }
        ++compared;
      }
    }
    for (size_t k = 0; k < want.checkpoints.size(); ++k) {
      EXPECT_EQ(got.checkpoints[k].t_s, want.checkpoints[k].t_s);
      EXPECT_EQ(got.checkpoints[k].run_index, want.checkpoints[k].run_index);
      for (int c = 0; c < kNumErrorComponents; ++c) {
        const size_t uc = static_cast<size_t>(c);
        if (tolerance[c] == 0.0) {
          EXPECT_EQ(got.checkpoints[k].values[0][uc], want.checkpoints[k].values[0][uc]);
        } else {
          EXPECT_NEAR(got.checkpoints[k].values[0][uc], want.checkpoints[k].values[0][uc],
                      tolerance[c]);
        }
      }
    }
    EXPECT_EQ(compared, want.epochs.size() * kNumErrorComponents);
    std::printf("%zu epochs: max |difference| position %.3g m, attitude %.3g rad\n",
                want.epochs.size(), max_position_diff_m, max_angle_diff_rad);
    // Not a trivially equal pair: the run has real errors (initial errors and sensor errors).
    const auto& final_values = want.checkpoints.back().values[0];
    EXPECT_GT(final_values[static_cast<size_t>(ErrorComponent::kPosition3d)], 1e-3);
  }
};

TEST_F(DatasetsRoundTrip, ScoreOfExportedNavigationReproducesMonteCarloRunWithInitialErrors) {
  Check(app::ParseJobJson(kJobJson), 9, 2);
}

TEST_F(DatasetsRoundTrip, ScoreReproducesStaticAlignmentRunOfTheExample) {
  // One hour at rest at 20 Hz; each run aligns over 5 min (levelling, gyrocompassing).
  Check(app::LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) +
                         "/examples/static_alignment_navigation.yaml")
            .job,
        1, 7);
}

TEST_F(DatasetsRoundTrip, ScoreReproducesSeed000MechanizationRun) {
  v1::Job job =
      app::LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/ship_seaway.json").job;
  job.mutable_sensor()->set_preset("seed000-fog-imu");
  job.mutable_monte_carlo()->set_runs(3);
  Check(job, 5, 1);
}

TEST_F(DatasetsServiceTest, SolutionMissingAnEpochIsInvalidArgumentNamingTheTime) {
  const v1::Job job = app::ParseJobJson(kJobJson);
  const v1::RunRef run = MakeRun(job, 9, 2);
  Export exported;
  ASSERT_TRUE(ExportRun(run, true, 0, &exported).ok());
  std::vector<double> rows;
  for (size_t r = 0; r < exported.header.navigation_rows(); ++r) {
    if (exported.navigation[r * 10] == 5.0) continue;  // the epoch at t = 5 s
    rows.insert(rows.end(), exported.navigation.begin() + static_cast<ptrdiff_t>(r * 10),
                exported.navigation.begin() + static_cast<ptrdiff_t>(r * 10 + 10));
  }
  ASSERT_EQ(rows.size() + 10, exported.navigation.size());
  v1::JobResult result;
  const std::vector<std::string> columns(exported.header.navigation_columns().begin(),
                                         exported.header.navigation_columns().end());
  const grpc::Status status = Score(run, columns, rows, 1000, &result);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("rows: no row at t_s = 5 s"), std::string::npos)
      << status.error_message();
}

TEST_F(DatasetsServiceTest, MalformedRequestsAreInvalidArgumentNamingTheField) {
  const v1::Job job = app::ParseJobJson(kJobJson);
  auto export_error = [&](const v1::RunRef& run, uint32_t rows_per_chunk) {
    Export out;
    return ExportRun(run, false, rows_per_chunk, &out);
  };
  auto expect = [](const grpc::Status& status, const std::string& prefix) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << prefix;
    EXPECT_EQ(status.error_message().rfind(prefix, 0), 0u) << status.error_message();
  };
  expect(export_error(MakeRun(job, 9, 5), 0), "run.run_index: 5");
  expect(export_error(MakeRun(job, 9, 0), 100000), "rows_per_chunk: 100000");
  v1::Job with_file = job;
  with_file.mutable_motion()->mutable_gnss_ins_sim_file()->set_path("/etc/passwd");
  expect(export_error(MakeRun(with_file, 9, 0), 0), "motion.gnss_ins_sim_file.path");
  v1::Job negative_rate = job;
  negative_rate.set_rate_hz(-100.0);
  expect(export_error(MakeRun(negative_rate, 9, 0), 0), "rate_hz: -100");

  const std::vector<std::string> columns = {"t_s",
                                            "lat_deg",
                                            "lon_deg",
                                            "height_m",
                                            "v_north_m_per_s",
                                            "v_east_m_per_s",
                                            "v_down_m_per_s",
                                            "roll_deg",
                                            "pitch_deg",
                                            "yaw_deg"};
  v1::JobResult result;
  std::vector<std::string> unknown = columns;
  unknown[3] = "alt_m";
  expect(Score(MakeRun(job, 9, 0), unknown, {}, 1, &result), "header.columns[3]: \"alt_m\"");
  std::vector<double> row = {0.0, 45.0, 7.0, 300.0, 0, 0, 0, 0, 0, 30.0};
  expect(Score(MakeRun(job, 9, 0), columns, {row.begin(), row.begin() + 7}, 1, &result),
         "rows[0].values: 7 values");
  row[2] = NAN;
  expect(Score(MakeRun(job, 9, 0), columns, row, 1, &result), "rows[0].lon_deg: nan");

  // Rows before the header.
  grpc::ClientContext context;
  auto writer = stub_->ScoreSolution(&context, &result);
  v1::ScoreSolutionRequest rows_first;
  rows_first.mutable_rows()->add_values(1.0);
  writer->Write(rows_first);
  writer->WritesDone();
  expect(writer->Finish(), "header: missing");
}

TEST_F(DatasetsServiceTest, RunBeyondTheSampleLimitIsResourceExhausted) {
  TestAuthenticator accept(true);
  server::ServerLimits limits;
  limits.max_job_samples = 1000;  // the job's run has ~3000 samples
  auto service = server::MakeDatasetsService(&accept, limits);
  InProcessServer server({service.get()});
  auto stub = v1::Datasets::NewStub(server.channel());
  v1::ExportRunRequest request;
  *request.mutable_run() = MakeRun(app::ParseJobJson(kJobJson), 9, 0);
  grpc::ClientContext context;
  auto reader = stub->ExportRun(&context, request);
  v1::ExportRunResponse response;
  EXPECT_FALSE(reader->Read(&response));
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
}

TEST(DatasetsServiceAuth, CallWithoutValidTokenIsUnauthenticated) {
  TestAuthenticator reject(false);
  auto service = server::MakeDatasetsService(&reject, server::ServerLimits{});
  InProcessServer server({service.get()});
  auto stub = v1::Datasets::NewStub(server.channel());
  grpc::ClientContext context;
  auto reader = stub->ExportRun(&context, v1::ExportRunRequest());
  v1::ExportRunResponse response;
  EXPECT_FALSE(reader->Read(&response));
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);
}

}  // namespace
}  // namespace driftlab
