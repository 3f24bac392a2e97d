// `driftlab datasheet FILE [--out MODEL.json]`: converts a datasheet summary (calib/datasheet.h
// documents the YAML keys) into the error model, prints every figure with its derived SI value,
// and writes the model as a job-schema sensor fragment {"sensor": {...}} (sensor_model_json.h).
// The fragment is checked by translating it back with the job loader's own validation, so a file
// this command writes is one `driftlab validate` accepts.
#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/app/sensor_model_json.h"
#include "driftlab/calib/datasheet.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

int RunDatasheet(const std::string& path, const std::string& out_path) {
  std::string json;
  try {
    CheckCommandOutputs({{path, "FILE"}}, {{out_path, "--out"}});
    const calib::DatasheetModel d = calib::LoadDatasheet(path);
    fmt::print("model {}: {}\n", d.model.name, d.model.description);
    fmt::print("  {:<32} {:<24} {:<24} {}\n", "key", "datasheet", "SI", "model field");
    for (const calib::DatasheetValue& v : d.values) {
      fmt::print("  {:<32} {:<24} {:<24} {}\n", v.key, v.text,
                 fmt::format("{:.6g} {}", v.value_si, v.si_unit), v.field);
    }
    json = app::SensorModelJson(d.model);
    app::ToImuErrorModel(app::ParseJobJson(json, "datasheet model"));
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  if (out_path.empty()) {
    fmt::print("{}", json);
    return kExitOk;
  }
  return WriteOutputText(out_path, json, "--out");
}

const RegisterCommand kDatasheet("datasheet", [](CLI::App& app) -> std::function<int()> {
  auto path = std::make_shared<std::string>();
  auto out_path = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "datasheet", "Datasheet summary (YAML, figures with units) -> sensor model (job fragment)");
  command->add_option("file", *path, "Datasheet summary (.yaml)")->required();
  command->add_option("--out", *out_path, "Write {\"sensor\": {...}} here (default: stdout)");
  return [path, out_path] { return RunDatasheet(*path, *out_path); };
});

}  // namespace
}  // namespace driftlab::cli
