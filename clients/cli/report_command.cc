// `driftlab report RESULT --out REPORT.html`: renders a result file as a self-contained HTML
// report (html_report.h). Exit 0, 2 for a bad result file, 1 when the report cannot be written.
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "commands.h"
#include "driftlab/app/result_check.h"
#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

struct ReportOptions {
  std::string result_path;
  std::string out_path;
};

int RunReport(const ReportOptions& options) {
  std::string html;
  try {
    const v1::JobResult result = app::ReadJobResult(options.result_path);
    app::VerifyResultStatistics(result, options.result_path);
    html = app::RenderHtmlReport(result);
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
  command->add_option("result", options->result_path, "Result file (JSON from `driftlab run`)")
      ->required();
  command->add_option("--out,-o", options->out_path, "HTML file to write")->required();
  return [options] { return RunReport(*options); };
});

}  // namespace
}  // namespace driftlab::cli
