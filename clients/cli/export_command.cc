// `driftlab export JOB --out DIR [--seed S] [--run R]`: the IMU data of run R of the job's Monte
// Carlo (the engine's SimulateMonteCarloRun, exactly as `driftlab run` computes that run), for
// users who bring their own navigation algorithm: imu.csv (measured increments and point samples),
// imu_ideal.csv (the error-free data), truth.csv (the reference trajectory), truth_groves.csv (the
// same in Groves' profile layout) and run.txt (what was run). The job is validated completely
// (ValidateJob) and DIR checked before the work (the files it will hold are none of the inputs; it
// takes new files); the files are written as a set (output_dir.h), so an error or Ctrl-C (exit
// status 130) leaves neither temporary files nor an incomplete set.
//
// With `--server ADDR [--token T] [--tls-ca F]` the server simulates the run (Datasets.ExportRun)
// and streams it: imu.csv and truth.csv (the same columns and numbers as the local files: the
// engine's CSV writer prints each double as the shortest text that reads back exactly),
// navigation.csv with --navigation (the engine's own navigation solution of that run, the layout
// `driftlab score` reads) and run.txt.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/app/translate.h"
#include "driftlab/io.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/simulate.h"
#include "driftlab/spec_error.h"
#include "interrupt.h"
#include "output_dir.h"
#include "remote.h"
#include "remote_client.h"

namespace driftlab::cli {
namespace {

struct ExportOptions {
  std::string job_path;
  std::string out_dir;
  std::optional<uint64_t> seed;
  uint32_t run_index = 0;
  bool navigation = false;
  RemoteOptions remote;
};

// A CSV file of rows of doubles under a header of column names, printed by the engine's writer.
class RowsCsvWriter : public CsvFile {
 public:
  // The engine's row buffer holds 20 numbers; the export layouts have at most 13 columns.
  static constexpr int kMaxColumns = 20;

  RowsCsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns)
      : CsvFile(path, fmt::format("{}", fmt::join(columns, ","))),
        columns_(static_cast<int>(columns.size())) {}

  // Writes values.size() / columns rows; `what` names the stream in errors.
  void WriteRows(const google::protobuf::RepeatedField<double>& values, const std::string& what) {
    if (columns_ == 0 || values.size() % columns_ != 0) {
      throw std::runtime_error(fmt::format("{}: chunk of {} values is not a multiple of {} columns",
                                           what, values.size(), columns_));
    }
    for (int i = 0; i < values.size(); i += columns_) Row(values.data() + i, columns_);
    rows_ += static_cast<uint64_t>(values.size() / columns_);
  }
  uint64_t rows() const { return rows_; }

 private:
  int columns_;
  uint64_t rows_ = 0;
};

void CheckColumns(const google::protobuf::RepeatedPtrField<std::string>& columns,
                  const std::string& what) {
  if (columns.empty() || columns.size() > RowsCsvWriter::kMaxColumns) {
    throw std::runtime_error(fmt::format("the server sent {} {} columns; expected 1 to {}",
                                         columns.size(), what, RowsCsvWriter::kMaxColumns));
  }
}

// Thrown when Ctrl-C (SIGINT) or SIGTERM arrived.
struct Interrupted {};

// The files the job names (the job file and its motion file), which the export must not replace.
std::vector<CommandPath> JobInputs(const std::string& job_path, const app::JobFile& file) {
  std::vector<CommandPath> inputs = {{job_path, "JOB"}};
  for (const CommandPath& p : app::JobInputFiles(file.job, file.base_dir)) inputs.push_back(p);
  return inputs;
}

int RunRemoteExport(const ExportOptions& options) {
  v1::ExportRunRequest request;
  std::unique_ptr<v1::Datasets::Stub> stub;
  std::optional<OutputDirectory> out;
  try {
    v1::RunRef* run = request.mutable_run();
    const app::JobFile file = app::LoadJobFile(options.job_path);
    *run->mutable_job() = file.job;
    if (options.seed) run->set_seed(*options.seed);
    run->set_run_index(options.run_index);
    request.set_include_navigation(options.navigation);
    std::vector<std::string> names = {"imu.csv", "truth.csv", "run.txt"};
    if (options.navigation) names.push_back("navigation.csv");
    std::vector<CommandPath> inputs = {{options.job_path, "JOB"}};
    out.emplace(options.out_dir, "--out", names, inputs);
    stub = v1::Datasets::NewStub(MakeChannel(options.remote));
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  const uint64_t seed = options.seed.value_or(app::JobSeed(request.run().job()));

  grpc::ClientContext context;
  PrepareContext(options.remote, &context);
  // Ctrl-C cancels the stream; the files written so far are removed below.
  InterruptWatch interrupt([&context] { context.TryCancel(); });
  std::unique_ptr<grpc::ClientReader<v1::ExportRunResponse>> reader =
      stub->ExportRun(&context, request);
  const std::filesystem::path dir(options.out_dir);
  v1::ExportRunResponse response;
  std::optional<v1::ExportHeader> header;
  std::unique_ptr<RowsCsvWriter> imu, truth, navigation;
  try {
    while (reader->Read(&response)) {
      if (response.has_header()) {
        if (header) throw std::runtime_error("the server sent a second export header");
        header = response.header();
        CheckColumns(header->imu_columns(), "IMU");
        CheckColumns(header->truth_columns(), "truth");
        if (options.navigation) CheckColumns(header->navigation_columns(), "navigation");
        const std::vector<std::string> imu_columns(header->imu_columns().begin(),
                                                   header->imu_columns().end());
        const std::vector<std::string> truth_columns(header->truth_columns().begin(),
                                                     header->truth_columns().end());
        imu = std::make_unique<RowsCsvWriter>(out->Path("imu.csv"), imu_columns);
        truth = std::make_unique<RowsCsvWriter>(out->Path("truth.csv"), truth_columns);
        if (options.navigation) {
          const std::vector<std::string> navigation_columns(header->navigation_columns().begin(),
                                                            header->navigation_columns().end());
          navigation =
              std::make_unique<RowsCsvWriter>(out->Path("navigation.csv"), navigation_columns);
        }
        continue;
      }
      if (!header) throw std::runtime_error("the server sent rows before the export header");
      const v1::ExportChunk& chunk = response.chunk();
      imu->WriteRows(chunk.imu(), "imu");
      truth->WriteRows(chunk.truth(), "truth");
      if (navigation) {
        navigation->WriteRows(chunk.navigation(), "navigation");
      } else if (!chunk.navigation().empty()) {
        throw std::runtime_error("the server sent navigation rows that were not asked for");
      }
    }
  } catch (const std::exception& e) {
    context.TryCancel();
    reader->Finish();
    imu.reset();
    truth.reset();
    navigation.reset();
    out.reset();
    fmt::print(stderr, "error: {}: {}\n", options.remote.server, e.what());
    return kExitFailure;
  }
  const grpc::Status status = reader->Finish();
  if (interrupt.interrupted()) {
    imu.reset();
    truth.reset();
    navigation.reset();
    out.reset();
    fmt::print(stderr, "cancelled: nothing written\n");
    return kExitCancelled;
  }
  if (!status.ok()) {
    imu.reset();
    truth.reset();
    navigation.reset();
    out.reset();
    return ReportRpcError(status, options.remote);
  }
  try {
    if (!header) throw std::runtime_error("the export stream ended without a header");
    auto check_rows = [](const RowsCsvWriter& writer, uint64_t expected, const char* name) {
      if (writer.rows() != expected) {
        throw std::runtime_error(fmt::format("{}: {} rows received, the header announced {}", name,
                                             writer.rows(), expected));
      }
    };
    check_rows(*imu, header->imu_rows(), "imu.csv");
    check_rows(*truth, header->truth_rows(), "truth.csv");
    imu->Close();
    truth->Close();
    if (navigation) {
      check_rows(*navigation, header->navigation_rows(), "navigation.csv");
      navigation->Close();
    }
    WriteOutputFile(out->Path("run.txt"),
                    fmt::format("job: {}\nname: {}\nserver: {}\nseed: {}\nrun: {}\n"
                                "rate_hz: {:.17g}\nsamples: {}\n",
                                options.job_path, request.run().job().name(), options.remote.server,
                                seed, options.run_index, header->rate_hz(), header->imu_rows()),
                    "--out");
    out->Commit();
  } catch (const std::exception& e) {
    imu.reset();
    truth.reset();
    navigation.reset();
    out.reset();
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  fmt::print("{}: seed {}, run {}: {} samples at {:g} Hz (from {})\n",
             request.run().job().name().empty() ? "(unnamed)" : request.run().job().name(), seed,
             options.run_index, header->imu_rows(), header->rate_hz(), options.remote.server);
  fmt::print("wrote imu.csv, truth.csv, {}run.txt to {}\n",
             options.navigation ? "navigation.csv, " : "", dir.string());
  return kExitOk;
}

int RunExport(const ExportOptions& options) {
  if (!options.remote.server.empty()) return RunRemoteExport(options);
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
    if (!spec.sensor) {
      throw SpecError("sensor", "(absent)",
                      "a sensor model (preset or parameters): export writes errored IMU data; "
                      "`driftlab simulate` writes the error-free data");
    }
    if (options.run_index >= spec.runs) {
      throw SpecError("--run", std::to_string(options.run_index),
                      "< monte_carlo.runs = " + std::to_string(spec.runs) +
                          " (run R of the job's Monte Carlo)");
    }
    out.emplace(options.out_dir, "--out",
                std::vector<std::string>{"truth.csv", "truth_groves.csv", "imu.csv",
                                         "imu_ideal.csv", "run.txt"},
                JobInputs(options.job_path, file));
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  const std::filesystem::path dir(options.out_dir);
  try {
    if (interrupt.interrupted()) throw Interrupted{};
    SimulationSummary summary;
    {
      TruthCsvWriter truth(out->Path("truth.csv"));
      GrovesProfileWriter groves(out->Path("truth_groves.csv"));
      ImuCsvWriter imu(out->Path("imu.csv"));
      ImuCsvWriter imu_ideal(out->Path("imu_ideal.csv"));
      summary = SimulateMonteCarloRun(
          spec, options.run_index, [&](const SimulationStep& step, const InsGnssFilter*) {
            if (interrupt.interrupted()) throw Interrupted{};
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
    }
    WriteOutputFile(
        out->Path("run.txt"),
        fmt::format("job: {}\nname: {}\nsensor model: {}\nseed: {}\nrun: {}\nrate_hz: {:.17g}\n"
                    "samples: {}\nduration_s: {:.17g}\n",
                    options.job_path, file.job.name(), spec.sensor->name, spec.seed,
                    options.run_index, spec.simulation.rate_hz, summary.steps + 1,
                    summary.duration_s),
        "--out");
    out->Commit();
    fmt::print("{}: sensor model {}, seed {}, run {}: {} samples at {:g} Hz ({:.3f} s)\n",
               file.job.name().empty() ? "(unnamed)" : file.job.name(), spec.sensor->name,
               spec.seed, options.run_index, summary.steps + 1, spec.simulation.rate_hz,
               summary.duration_s);
    fmt::print("wrote imu.csv, imu_ideal.csv, truth.csv, truth_groves.csv, run.txt to {}\n",
               dir.string());
  } catch (const Interrupted&) {
    out.reset();  // removes the files written so far
    fmt::print(stderr, "cancelled: nothing written\n");
    return kExitCancelled;
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
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Random seed (default: the job's monte_carlo.seed)");
  AddUnsignedOption(command, "--run", &options->run_index, "Run index (default 0)");
  CLI::Option* server = AddRemoteOptions(command, &options->remote, /*server_required=*/false);
  command
      ->add_flag("--navigation", options->navigation,
                 "Also write navigation.csv, the engine's navigation solution of this run "
                 "(with --server)")
      ->needs(server);
  return [options] { return RunExport(*options); };
});

}  // namespace
}  // namespace driftlab::cli
