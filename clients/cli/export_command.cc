// `driftlab export JOB --out DIR [--seed S] [--run R]`: the IMU data of one seeded run of the job's
// sensor model, for users who bring their own navigation algorithm: imu.csv (measured increments
// and point samples), imu_ideal.csv (the error-free data), truth.csv (the reference trajectory),
// truth_groves.csv (the same in Groves' profile layout) and run.txt (what was run). The job is
// validated completely before DIR is created.
#include <fmt/format.h>
#include <fmt/os.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "commands.h"
#include "driftlab/io.h"
#include "driftlab/jobspec/job_file.h"
#include "driftlab/jobspec/sensor_model.h"
#include "driftlab/jobspec/translate.h"
#include "driftlab/simulate.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

struct ExportOptions {
  std::string job_path;
  std::string out_dir;
  std::optional<uint64_t> seed;
  uint32_t run_index = 0;
};

int RunExport(const ExportOptions& options) {
  jobspec::JobFile file;
  SimulationSpec spec;
  std::optional<SensorRun> sensor;
  try {
    file = jobspec::LoadJobFile(options.job_path);
    spec = jobspec::ValidateJob(file);
    std::optional<ImuErrorModel> model = jobspec::ToImuErrorModel(file.job);
    if (!model) {
      throw SpecError("sensor", "(absent)",
                      "a sensor model (preset or parameters): export writes errored IMU data; "
                      "`driftlab simulate` writes the error-free data");
    }
    sensor = SensorRun{*std::move(model), options.seed.value_or(jobspec::JobSeed(file.job)),
                       options.run_index};
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  const std::filesystem::path dir(options.out_dir);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    fmt::print(stderr, "error: {}: cannot create the output directory ({})\n", options.out_dir,
               error.message());
    return kExitFailure;
  }
  try {
    TruthCsvWriter truth(dir / "truth.csv");
    GrovesProfileWriter groves(dir / "truth_groves.csv");
    ImuCsvWriter imu(dir / "imu.csv");
    ImuCsvWriter imu_ideal(dir / "imu_ideal.csv");
    const SimulationSummary summary =
        RunSimulation(spec, &*sensor, [&](const SimulationStep& step) {
          const double t_s = step.truth->t_s;
          truth.Write(*step.truth);
          groves.Write(*step.truth);
          imu.Write(t_s, *step.measured_increment, *step.measured_sample);
          imu_ideal.Write(t_s, *step.increment, *step.sample);
        });
    truth.Close();
    groves.Close();
    imu.Close();
    imu_ideal.Close();
    {
      auto run = fmt::output_file((dir / "run.txt").string());
      run.print("job: {}\nname: {}\nsensor model: {}\nseed: {}\nrun: {}\nrate_hz: {:.17g}\n",
                options.job_path, file.job.name(), sensor->model.name, sensor->seed,
                sensor->run_index, spec.rate_hz);
      run.print("samples: {}\nduration_s: {:.17g}\n", summary.steps + 1, summary.duration_s);
    }
    fmt::print("{}: sensor model {}, seed {}, run {}: {} samples at {:g} Hz ({:.3f} s)\n",
               file.job.name().empty() ? "(unnamed)" : file.job.name(), sensor->model.name,
               sensor->seed, sensor->run_index, summary.steps + 1, spec.rate_hz,
               summary.duration_s);
    fmt::print("wrote imu.csv, imu_ideal.csv, truth.csv, truth_groves.csv, run.txt to {}\n",
               dir.string());
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return kExitOk;
}

const RegisterCommand kExport("export", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* command = app.add_subcommand(
      "export",
      "Write the errored IMU data of one seeded run of the job's sensor model (imu.csv), the "
      "error-free data (imu_ideal.csv) and the truth (truth.csv, truth_groves.csv)");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command->add_option("--out,-o", options->out_dir, "Output directory (created if absent)")
      ->required();
  command->add_option("--seed", options->seed, "Random seed (default: the job's monte_carlo.seed)");
  command->add_option("--run", options->run_index, "Run index")->capture_default_str();
  return [options] { return RunExport(*options); };
});

}  // namespace
}  // namespace driftlab::cli
