// driftlab: command-line client. Parses the command line and dispatches to one file per command.
#include <CLI/CLI.hpp>
#include <string>

#include "commands.h"

int main(int argc, char** argv) {
  CLI::App app{"driftlab: inertial navigation error analysis"};
  app.set_version_flag("--version", std::string("driftlab ") + DRIFTLAB_VERSION);
  app.require_subcommand(1);

  std::string job_path;
  std::string out_dir = "driftlab-out";

  CLI::App* simulate =
      app.add_subcommand("simulate",
                         "Run a job's motion through its mechanization on error-free "
                         "IMU data; write truth.csv, imu.csv, nav.csv, errors.csv");
  simulate->add_option("job", job_path, "Job file (.json, .yaml, .yml)")->required();
  simulate->add_option("--out,-o", out_dir, "Output directory (created if absent)")
      ->capture_default_str();

  CLI::App* validate = app.add_subcommand("validate", "Check a job file; print OK or the error");
  validate->add_option("job", job_path, "Job file (.json, .yaml, .yml)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    // --help and --version exit 0; a wrong command line is bad input like a bad job.
    return status == 0 ? driftlab::cli::kExitOk : driftlab::cli::kExitBadJob;
  }
  if (simulate->parsed()) return driftlab::cli::RunSimulate(job_path, out_dir);
  return driftlab::cli::RunValidate(job_path);
}
