// `driftlab simulate JOB --out DIR [--seed S] [--run N]`: run N of the job's Monte Carlo, sample
// by sample, exactly as `driftlab run` computes it (the engine's SimulateMonteCarloRun: the run's
// sensor errors, initial errors, alignment, aiding and filter): truth.csv, imu.csv, imu_ideal.csv
// (with a sensor model), nav.csv and errors.csv (from the navigation start on) and, for the
// INS/GNSS EKF, filter.csv (its sensor-error estimates and the 1-sigma of its navigation errors).
// The job is validated completely (ValidateJob) and DIR checked (the files it will hold are none of
// the inputs, it takes new files) before the work, so a bad job or output writes nothing; the files
// are written as a set (output_dir.h), so an error or Ctrl-C leaves neither temporary files nor an
// incomplete set (exit status 130 on Ctrl-C).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/translate.h"
#include "driftlab/io.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/simulate.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "interrupt.h"
#include "output_dir.h"
#include "remote.h"

namespace driftlab::cli {
namespace {

// filter.csv: the EKF's estimates and the sigma of its navigation errors at every sample from the
// navigation start (the covariance as last propagated: at the output epochs and aiding updates).
class FilterCsvWriter : public CsvFile {
 public:
  explicit FilterCsvWriter(const std::filesystem::path& path)
      : CsvFile(path,
                "t_s,accel_bias_x_m_per_s2,accel_bias_y_m_per_s2,accel_bias_z_m_per_s2,"
                "gyro_bias_x_rad_per_s,gyro_bias_y_rad_per_s,gyro_bias_z_rad_per_s,"
                "sigma_north_m,sigma_east_m,sigma_down_m,sigma_v_north_m_per_s,"
                "sigma_v_east_m_per_s,sigma_v_down_m_per_s,sigma_psi_north_rad,"
                "sigma_psi_east_rad,sigma_psi_down_rad") {}
  void Write(double t_s, const InsGnssFilter& filter) {
    double row[16];
    row[0] = t_s;
    for (int i = 0; i < 3; ++i) {
      row[1 + i] = filter.accel_bias()[i];
      row[4 + i] = filter.gyro_bias()[i];
    }
    for (int i = 0; i < 9; ++i) row[7 + i] = std::sqrt(std::max(0.0, filter.P()(i, i)));
    Row(row, 16);
  }
};

void PrintSummary(const app::JobFile& file, const MonteCarloSpec& mc, uint32_t run,
                  const SimulationSummary& summary, const std::filesystem::path& out_dir,
                  bool filter) {
  const SimulationSpec& spec = mc.simulation;
  const std::string name = file.job.name().empty() ? "(unnamed)" : file.job.name();
  fmt::print("{}: {:.3f} s, {} steps at {:g} Hz, {} mechanization, {} earth\n", name,
             summary.duration_s, summary.steps, spec.rate_hz,
             spec.mechanization == MechanizationKind::kNed ? "NED" : "SEED000",
             spec.motion.earth_model == EarthModel::kWgs84 ? "WGS84" : "FLAT");
  if (mc.sensor) {
    fmt::print("sensor model {}, seed {}, run {} of {} of the job's Monte Carlo\n", mc.sensor->name,
               mc.seed, run, mc.runs);
  } else {
    fmt::print(
        "error-free IMU data (the job has no sensor model), seed {}, run {} of {} of the "
        "job's Monte Carlo\n",
        mc.seed, run, mc.runs);
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
  fmt::print("wrote truth.csv, imu.csv, {}nav.csv, errors.csv{} to {}\n",
             mc.sensor ? "imu_ideal.csv, " : "", filter ? ", filter.csv" : "", out_dir.string());
}

struct SimulateOptions {
  std::string job_path;
  std::string out_dir = "driftlab-out";
  std::optional<uint64_t> seed;
  uint32_t run_index = 0;
};

// Thrown from the step callback when Ctrl-C (SIGINT) or SIGTERM arrived.
struct Interrupted {};

int RunSimulate(const SimulateOptions& options) {
  // From here on Ctrl-C ends the command through the cleanup below, not by the default action.
  InterruptWatch interrupt([] {});
  app::JobFile file;
  MonteCarloSpec spec;
  std::optional<OutputDirectory> out;
  try {
    file = app::LoadJobFile(options.job_path);
    app::JobValidationOptions validation;
    validation.overrides.seed = options.seed;
    spec = app::ValidateJob(file, validation).spec;
    if (options.run_index >= spec.runs) {
      throw SpecError("--run", std::to_string(options.run_index),
                      "< monte_carlo.runs = " + std::to_string(spec.runs) +
                          " (run N of the job's Monte Carlo)");
    }
    std::vector<std::string> names = {"truth.csv", "imu.csv", "nav.csv", "errors.csv"};
    if (spec.sensor) names.push_back("imu_ideal.csv");
    if (spec.filter == NavigationFilterKind::kInsGnssEkf) names.push_back("filter.csv");
    std::vector<CommandPath> inputs = {{options.job_path, "JOB"}};
    for (const CommandPath& p : app::JobInputFiles(file.job, file.base_dir)) inputs.push_back(p);
    out.emplace(options.out_dir, "--out", names, inputs);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  const std::filesystem::path dir(options.out_dir);
  try {
    if (interrupt.interrupted()) throw Interrupted{};
    const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
    SimulationSummary summary;
    {
      SimulationCsvWriters writers(out->directory(), /*ideal_imu=*/spec.sensor.has_value());
      std::optional<FilterCsvWriter> filter_csv;
      if (ekf) filter_csv.emplace(out->Path("filter.csv"));
      summary = SimulateMonteCarloRun(spec, options.run_index,
                                      [&](const SimulationStep& step, const InsGnssFilter* filter) {
                                        if (interrupt.interrupted()) throw Interrupted{};
                                        writers.Write(step);
                                        if (filter_csv && filter != nullptr)
                                          filter_csv->Write(step.truth->t_s, *filter);
                                      });
      writers.Close();
      if (filter_csv) filter_csv->Close();
    }
    out->Commit();
    PrintSummary(file, spec, options.run_index, summary, dir, ekf);
  } catch (const Interrupted&) {
    out.reset();  // removes the files written so far
    fmt::print(stderr, "cancelled: nothing written\n");
    return kExitCancelled;
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
      "Run N of the job's Monte Carlo sample by sample, exactly as `run` computes it (sensor "
      "errors, initial errors, alignment, aiding, filter); write truth.csv, imu.csv, nav.csv, "
      "errors.csv (and filter.csv for the INS/GNSS EKF)");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command->add_option("--out,-o", options->out_dir, "Output directory (created if absent)")
      ->capture_default_str();
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Random seed (default: the job's monte_carlo.seed)");
  AddUnsignedOption(command, "--run", &options->run_index,
                    "Run index N (< monte_carlo.runs) of the job's Monte Carlo")
      ->capture_default_str();
  return [options] { return RunSimulate(*options); };
});

}  // namespace
}  // namespace driftlab::cli
