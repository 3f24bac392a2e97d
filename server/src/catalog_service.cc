// Catalog service: the engine's IMU presets (presets.h) and the example jobs the server can run.
//
// Presets: name and description as the catalogue holds them; `grade` is the preset's own grade for
// the five grade presets and otherwise the gyro grade of seed 001's table (SEEDS.md, seed 001
// grade tables) that both its angle random walk (rate grade > 0.5 deg/sqrt(h), tactical 0.05-0.5,
// aviation 0.001-0.05, navigation < 0.001) and its bias instability (rate > 10 deg/h, tactical
// 1-10, aviation/navigation < 0.01; the table's gap 0.01-1 counts as tactical) meet; `source` is
// the document the figures come from, read from the description ("Source: ..." or the parenthesised
// datasheet/brochure reference). GetPreset's sensor model is the ImuErrorModel in the job schema's
// datasheet units (sensor_model_json.h).
//
// Examples: every *.json / *.yaml / *.yml in the examples directory, parsed with the job loader
// (app::LoadJobFile) when the service is built; files that fail to parse and jobs that name
// motion files (the server reads no client-named files) are left out.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/sensor_model_json.h"
#include "driftlab/presets.h"
#include "driftlab/server/data_services.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::server {
namespace {

// The five grade presets of presets.cc and their grade names.
constexpr std::pair<std::string_view, std::string_view> kGradePresets[] = {
    {"rate-grade", "rate"},
    {"industrial", "industrial"},
    {"tactical", "tactical"},
    {"aviation", "aviation"},
    {"navigation", "navigation"}};

std::string Grade(const ImuErrorModel& model) {
  for (const auto& [name, grade] : kGradePresets) {
    if (model.name == name) return std::string(grade);
  }
  // Grades from best (3) to worst (0); each figure must meet the grade, so the worse one counts.
  constexpr const char* kGrades[] = {"rate", "tactical", "aviation", "navigation"};
  const double arw_deg_per_sqrt_h = FromSi(model.gyro.white_noise_density, "deg/sqrt(h)");
  if (!(arw_deg_per_sqrt_h > 0.0)) return "unclassified";
  int grade = arw_deg_per_sqrt_h > 0.5      ? 0
              : arw_deg_per_sqrt_h >= 0.05  ? 1
              : arw_deg_per_sqrt_h >= 0.001 ? 2
                                            : 3;
  const double bi_deg_per_h = FromSi(model.gyro.bias_flicker.bias_instability, "deg/h");
  if (bi_deg_per_h > 0.0) {
    // Bias instability: rate > 10 deg/h, tactical 1-10 (and the table's gap up to 0.01),
    // aviation/navigation < 0.01 deg/h.
    grade = std::min(grade, bi_deg_per_h > 10.0 ? 0 : bi_deg_per_h > 0.01 ? 1 : 3);
  }
  return kGrades[grade];
}

bool IsReference(std::string_view text) {
  return text.find("datasheet") != std::string_view::npos ||
         text.find("brochure") != std::string_view::npos ||
         text.find("leaflet") != std::string_view::npos;
}

// "seed 001 grade tables" from "... Source: seed 001 grade tables, column ...", else the
// parenthesised references "(ADIS16470 datasheet Rev. C)" (the part after a "; ", up to ",
// values"), joined with "; " and preceded by a "seed NNN" the description names.
std::string Source(const std::string& description) {
  constexpr std::string_view kSource = "Source: ";
  const size_t at = description.find(kSource);
  if (at != std::string::npos) {
    const size_t begin = at + kSource.size();
    const size_t end =
        std::min(description.find_first_of(",;:", begin), description.find(". ", begin));
    return description.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
  }
  std::vector<std::string> parts;
  // "Pico-satellite IMU of seed 003: ADXRS300 gyros (...)": a seed named before any reference.
  const size_t seed = description.find("seed 00");
  if (seed < description.find('(')) parts.push_back(description.substr(seed, 8));
  for (size_t open = description.find('('); open != std::string::npos;
       open = description.find('(', open + 1)) {
    const size_t close = description.find(')', open);
    if (close == std::string::npos) break;
    const std::string inner = description.substr(open + 1, close - open - 1);
    // The first "; "-separated part that names a document.
    for (size_t begin = 0; begin < inner.size();) {
      const size_t end = std::min(inner.find("; ", begin), inner.size());
      std::string part = inner.substr(begin, end - begin);
      if (IsReference(part) && !std::islower(static_cast<unsigned char>(part[0]))) {
        parts.push_back(part.substr(0, part.find(", values")));
        break;
      }
      begin = end + 2;
    }
  }
  if (parts.empty()) return description.substr(0, description.find(". "));
  return fmt::format("{}", fmt::join(parts, "; "));
}

void FillSummary(const ImuErrorModel& model, v1::PresetSummary* summary) {
  summary->set_name(model.name);
  summary->set_grade(Grade(model));
  summary->set_description(model.description);
  summary->set_source(Source(model.description));
}

bool ReferencesFiles(const v1::Job& job) {
  return job.motion().has_gnss_ins_sim_file() || job.motion().has_truth_profile_file();
}

std::vector<v1::Example> LoadExamples(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".json" || ext == ".yaml" || ext == ".yml")) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<v1::Example> examples;
  for (const std::filesystem::path& path : files) {
    try {
      app::JobFile file = app::LoadJobFile(path);
      if (ReferencesFiles(file.job)) continue;
      v1::Example& example = examples.emplace_back();
      example.set_name(path.stem().string());
      example.set_description(file.job.description());
      *example.mutable_job() = std::move(file.job);
    } catch (const SpecError&) {
      // Not a job the server can offer; `driftlab validate FILE` reports why.
    }
  }
  return examples;
}

class CatalogService final : public v1::Catalog::Service {
 public:
  CatalogService(const Authenticator* auth, const std::filesystem::path& examples_dir)
      : auth_(auth), examples_(LoadExamples(examples_dir)) {}

  grpc::Status ListPresets(grpc::ServerContext* context, const v1::ListPresetsRequest*,
                           v1::ListPresetsResponse* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    for (v1::PresetSummary& summary : PresetSummaries()) {
      *response->add_presets() = std::move(summary);
    }
    return grpc::Status::OK;
  }

  grpc::Status GetPreset(grpc::ServerContext* context, const v1::GetPresetRequest* request,
                         v1::Preset* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    std::optional<v1::Preset> preset = FindPreset(request->name());
    if (!preset) {
      std::vector<std::string> names;
      for (const ImuErrorModel& m : ImuCatalogue()) names.push_back(m.name);
      return grpc::Status(grpc::StatusCode::NOT_FOUND,
                          fmt::format("name: unknown preset \"{}\"; presets: {}", request->name(),
                                      fmt::join(names, ", ")));
    }
    *response = std::move(*preset);
    return grpc::Status::OK;
  }

  grpc::Status ListExamples(grpc::ServerContext* context, const v1::ListExamplesRequest*,
                            v1::ListExamplesResponse* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    for (const v1::Example& example : examples_) *response->add_examples() = example;
    return grpc::Status::OK;
  }

 private:
  const Authenticator* auth_;
  const std::vector<v1::Example> examples_;
};

}  // namespace

std::vector<v1::PresetSummary> PresetSummaries() {
  std::vector<v1::PresetSummary> summaries;
  for (const ImuErrorModel& model : ImuCatalogue()) FillSummary(model, &summaries.emplace_back());
  return summaries;
}

std::optional<v1::Preset> FindPreset(const std::string& name) {
  const std::vector<ImuErrorModel>& catalogue = ImuCatalogue();
  const auto it = std::find_if(catalogue.begin(), catalogue.end(),
                               [&](const ImuErrorModel& m) { return m.name == name; });
  if (it == catalogue.end()) return std::nullopt;
  v1::Preset preset;
  FillSummary(*it, preset.mutable_summary());
  *preset.mutable_sensor() = app::ToSensorModelProto(*it);
  return preset;
}

std::unique_ptr<v1::Catalog::Service> MakeCatalogService(const Authenticator* auth,
                                                         std::filesystem::path examples_dir) {
  return std::make_unique<CatalogService>(auth, examples_dir);
}

}  // namespace driftlab::server
