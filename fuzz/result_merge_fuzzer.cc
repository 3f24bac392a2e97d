// Fuzz target: result files (fuzz_targets.h), as `report`, `gate` and `merge` read them. The input
// is two result texts separated by a NUL byte (a JSON text holds none): each is parsed and
// validated (ParseJobResultJson), rendered (RenderHtmlReport) and its statistics checked against
// its sums (VerifyResultStatistics); the pair of checked results is gated (RunGate with
// the default rules, its table and JUnit XML) and merged as two shards (MergeJobResults).
#include <optional>
#include <string>
#include <string_view>

#include "driftlab/app/gate.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/result_check.h"
#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "driftlab/spec_error.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {
namespace {

// The result if it is valid and its statistics agree with its sums and per-run values (what
// `gate` and `merge` require); a valid result is rendered either way.
std::optional<v1::JobResult> ReadOne(std::string_view text, std::string_view source) {
  v1::JobResult result;
  try {
    result = app::ParseJobResultJson(text, source);
    app::RenderHtmlReport(result);
  } catch (const SpecError&) {
    return std::nullopt;
  }
  try {
    app::VerifyResultStatistics(result, std::string(source));
  } catch (const SpecError&) {
    return std::nullopt;
  }
  return result;
}

}  // namespace

void FuzzResultMerge(const uint8_t* data, size_t size) {
  const std::string_view text = AsText(data, size);
  const size_t nul = text.find('\0');
  const std::optional<v1::JobResult> first = ReadOne(text.substr(0, nul), "first.json");
  if (nul == std::string_view::npos) return;
  const std::optional<v1::JobResult> second = ReadOne(text.substr(nul + 1), "second.json");
  if (!first || !second) return;
  try {
    app::GateOptions options;
    options.allow_different_job = true;
    const app::GateReport report = app::RunGate(*first, *second, app::DefaultGateRules(), options);
    app::FormatGateTable(report);
    app::RenderJunitXml(report);
  } catch (const SpecError&) {
  }
  try {
    const v1::JobResult merged =
        app::MergeJobResults({*first, *second}, {"first.json", "second.json"}, "fuzz");
    app::ValidateJobResult(merged);
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
