// `driftlab report FILE.json --out REPORT.html`: renders a file as a self-contained HTML report.
// FILE is a Monte-Carlo result (`driftlab run --out`, `driftlab result --out`: html_report.h), a
// calibration result (`driftlab calibrate --out`) or a noise-model fit (`driftlab allan --fit
// --fit-json`): calibration_report.h, without the raw-recording plots, which need the recording,
// and a noise fit titled by its columns (NoiseFitTitle). The kind is the message the JSON parses
// as (unknown fields refused, so each file is exactly one kind); a Monte-Carlo result is also
// validated (ValidateJobResult) and its statistics checked against its exact sums and per-run
// values (VerifyResultStatistics). The bytes depend only on the file's content: the server's web
// pages serve the same report for the same stored result. Exit 0, 2 for a bad file, 1 when the
// report cannot be written.
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <memory>
#include <string>

#include "commands.h"
#include "driftlab/app/json_syntax.h"
#include "driftlab/app/result_check.h"
#include "driftlab/app/result_file.h"
#include "driftlab/input_files.h"
#include "driftlab/report/calibration_report.h"
#include "driftlab/report/html_report.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

struct ReportOptions {
  std::string result_path;
  std::string out_path;
};

template <typename Message>
bool ParsesAs(const std::string& json, Message* message) {
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  return google::protobuf::util::JsonStringToMessage(json, message, options).ok();
}

std::string Render(const std::string& path) {
  const std::string json = ReadInputFile(path, kMaxResultFileBytes, path);
  app::CheckJsonSyntax(json, path, "result JSON");  // depth and syntax bounded before parsing
  v1::CalibrationResult calibration;
  v1::NoiseModelFit fit;
  v1::JobResult probe;
  if (!ParsesAs(json, &probe)) {
    if (ParsesAs(json, &calibration)) return app::RenderCalibrationReport(calibration);
    if (ParsesAs(json, &fit)) return app::RenderNoiseFitReport(fit, app::NoiseFitTitle(fit));
  }
  // A Monte-Carlo result, or a file that is none of the three: the result reader's message. The
  // statistics are checked against the exact sums and per-run values before they are rendered.
  const v1::JobResult result = app::ParseJobResultJson(json, path);
  app::VerifyResultStatistics(result, path);
  return app::RenderHtmlReport(result);
}

int RunReport(const ReportOptions& options) {
  std::string html;
  try {
    CheckCommandOutputs({{options.result_path, "RESULT"}}, {{options.out_path, "--out"}});
    html = Render(options.result_path);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  return WriteOutputText(options.out_path, html, "--out");
}

const RegisterCommand kReport("report", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<ReportOptions>();
  CLI::App* command =
      app.add_subcommand("report", "Render a result file as a self-contained HTML report");
  command
      ->add_option("result", options->result_path,
                   "Result file: JSON from `driftlab run` / `result`, `calibrate --out` or "
                   "`allan --fit --fit-json`")
      ->required();
  command->add_option("--out,-o", options->out_path, "HTML file to write")->required();
  return [options] { return RunReport(*options); };
});

}  // namespace
}  // namespace driftlab::cli
