// `driftlab validate JOB`: prints "OK" or the first error of the job (exit 2). The check is
// app::ValidateJob, the one every entry (run, simulate, export, the server) makes: a job that
// validates runs.
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

int RunValidate(const std::string& job_path) {
  try {
    const app::JobFile file = app::LoadJobFile(job_path);
    app::ValidateJob(file);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  fmt::print("OK\n");
  return kExitOk;
}

const RegisterCommand kValidate("validate", [](CLI::App& app) -> std::function<int()> {
  auto job_path = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand("validate", "Check a job file; print OK or the error");
  command->add_option("job", *job_path, "Job file (.json, .yaml, .yml)")->required();
  return [job_path] { return RunValidate(*job_path); };
});

}  // namespace
}  // namespace driftlab::cli
