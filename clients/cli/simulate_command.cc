// `driftlab simulate JOB --out DIR`: the job's motion through its mechanization on error-free IMU
// data. The job is validated completely (fields and the planned motion) before DIR is created, so
// a bad job writes nothing.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/app/translate.h"
#include "driftlab/io.h"
#include "driftlab/simulate.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::cli {
namespace {

void PrintSummary(const app::JobFile& file, const SimulationSpec& spec, const SensorRun* sensor,
                  const SimulationSummary& summary, const std::filesystem::path& out_dir) {
  const std::string name = file.job.name().empty() ? "(unnamed)" : file.job.name();
  fmt::print("{}: {:.3f} s, {} steps at {:g} Hz, {} mechanization, {} earth\n", name,
             summary.duration_s, summary.steps, spec.rate_hz,
             spec.mechanization == MechanizationKind::kNed ? "NED" : "SEED000",
             spec.motion.earth_model == EarthModel::kWgs84 ? "WGS84" : "FLAT");
  if (sensor != nullptr) {
    fmt::print("sensor model {}, seed {}, run {}\n", sensor->model.name, sensor->seed,
               sensor->run_index);
  } else {
    fmt::print("error-free IMU data (the job has no sensor model)\n");
  }
  const NavError& final_error = summary.final_error;
  fmt::print("{:<26}{:>14}{:>14}\n", "error", "final", "max");
  auto row = [](const char* label, double final_value, double max_value) {
    fmt::print("{:<26}{:>14.4e}{:>14.4e}\n", label, final_value, max_value);
  };
  row("horizontal position [m]", summary.final_horizontal_position_m,
      summary.max_horizontal_position_m);
  row("vertical position [m]", std::abs(final_error.r_ned_m.z()), summary.max_vertical_position_m);
  row("velocity [m/s]", final_error.v_ned_m_per_s.norm(), summary.max_velocity_m_per_s);
  row("roll [deg]", std::abs(final_error.euler_rad.x()) * kRadToDeg,
      summary.max_abs_euler_rad.x() * kRadToDeg);
  row("pitch [deg]", std::abs(final_error.euler_rad.y()) * kRadToDeg,
      summary.max_abs_euler_rad.y() * kRadToDeg);
  row("yaw [deg]", std::abs(final_error.euler_rad.z()) * kRadToDeg,
      summary.max_abs_euler_rad.z() * kRadToDeg);
  fmt::print("wrote truth.csv, imu.csv, {}nav.csv, errors.csv to {}\n",
             sensor != nullptr ? "imu_ideal.csv, " : "", out_dir.string());
}

struct SimulateOptions {
  std::string job_path;
  std::string out_dir = "driftlab-out";
  std::optional<uint64_t> seed;
  uint32_t run_index = 0;
};

int RunSimulate(const SimulateOptions& options) {
  const std::string& out_dir = options.out_dir;
  app::JobFile file;
  SimulationSpec spec;
  std::optional<SensorRun> sensor;
  try {
    file = app::LoadJobFile(options.job_path);
    spec = app::ValidateJob(file);
    if (std::optional<ImuErrorModel> model = app::ToImuErrorModel(file.job)) {
      sensor = SensorRun{*std::move(model), options.seed.value_or(app::JobSeed(file.job)),
                         options.run_index};
    }
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  const std::filesystem::path dir(out_dir);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    fmt::print(stderr, "error: {}: cannot create the output directory ({})\n", out_dir,
               error.message());
    return kExitFailure;
  }
  try {
    const SensorRun* run = sensor ? &*sensor : nullptr;
    SimulationCsvWriters writers(dir, /*ideal_imu=*/run != nullptr);
    const SimulationSummary summary =
        RunSimulation(spec, run, [&writers](const SimulationStep& step) { writers.Write(step); });
    writers.Close();
    PrintSummary(file, spec, run, summary, dir);
  } catch (const SpecError& e) {
    // The engine may still reject a job after planning (a check made while integrating).
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return kExitOk;
}

const RegisterCommand kSimulate("simulate", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Run a job's motion through its mechanization (one seeded run of its sensor model, or "
      "error-free IMU data without one); write truth.csv, imu.csv, nav.csv, errors.csv");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command->add_option("--out,-o", options->out_dir, "Output directory (created if absent)")
      ->capture_default_str();
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Random seed (default: the job's monte_carlo.seed)");
  AddUnsignedOption(command, "--run", &options->run_index, "Run index of the sensor errors")
      ->capture_default_str();
  return [options] { return RunSimulate(*options); };
});

}  // namespace
}  // namespace driftlab::cli
