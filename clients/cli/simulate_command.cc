// `driftlab simulate JOB --out DIR`: the job's motion through its mechanization on error-free IMU
// data. The job is validated completely (fields and the planned motion) before DIR is created, so
// a bad job writes nothing.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include "commands.h"
#include "driftlab/io.h"
#include "driftlab/jobspec/job_file.h"
#include "driftlab/jobspec/translate.h"
#include "driftlab/simulate.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

void PrintSummary(const jobspec::JobFile& file, const SimulationSpec& spec,
                  const SimulationSummary& summary, const std::filesystem::path& out_dir) {
  const std::string name = file.job.name().empty() ? "(unnamed)" : file.job.name();
  fmt::print("{}: {:.3f} s, {} steps at {:g} Hz, {} mechanization, {} earth\n", name,
             summary.duration_s, summary.steps, spec.rate_hz,
             spec.mechanization == MechanizationKind::kNed ? "NED" : "SEED000",
             spec.motion.earth_model == EarthModel::kWgs84 ? "WGS84" : "FLAT");
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
  fmt::print("wrote truth.csv, imu.csv, nav.csv, errors.csv to {}\n", out_dir.string());
}

int RunSimulate(const std::string& job_path, const std::string& out_dir) {
  jobspec::JobFile file;
  SimulationSpec spec;
  try {
    file = jobspec::LoadJobFile(job_path);
    spec = jobspec::ValidateJob(file);
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
    SimulationCsvWriters writers(dir);
    const SimulationSummary summary = RunErrorFreeSimulation(
        spec, [&writers](const SimulationStep& step) { writers.Write(step); });
    writers.Close();
    PrintSummary(file, spec, summary, dir);
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
  struct Options {
    std::string job_path;
    std::string out_dir = "driftlab-out";
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Run a job's motion through its mechanization (one seeded run of its sensor model, or "
      "error-free IMU data without one); write truth.csv, imu.csv, nav.csv, errors.csv");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command->add_option("--out,-o", options->out_dir, "Output directory (created if absent)")
      ->capture_default_str();
  return [options] { return RunSimulate(options->job_path, options->out_dir); };
});

}  // namespace
}  // namespace driftlab::cli
