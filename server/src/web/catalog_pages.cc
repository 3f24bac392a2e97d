// The IMU catalogue (Catalog.ListPresets / GetPreset, data_services.h): list and preset pages.
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include "web/pages.h"

namespace driftlab::server::web {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

std::string ScalarText(const Message& m, const FieldDescriptor& f, int index) {
  const auto& r = *m.GetReflection();
  const bool rep = f.is_repeated();
  switch (f.cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return fmt::format("{:.10g}", rep ? r.GetRepeatedDouble(m, &f, index) : r.GetDouble(m, &f));
    case FieldDescriptor::CPPTYPE_FLOAT:
      return fmt::format("{:.7g}", rep ? r.GetRepeatedFloat(m, &f, index) : r.GetFloat(m, &f));
    case FieldDescriptor::CPPTYPE_INT32:
      return std::to_string(rep ? r.GetRepeatedInt32(m, &f, index) : r.GetInt32(m, &f));
    case FieldDescriptor::CPPTYPE_INT64:
      return std::to_string(rep ? r.GetRepeatedInt64(m, &f, index) : r.GetInt64(m, &f));
    case FieldDescriptor::CPPTYPE_UINT32:
      return std::to_string(rep ? r.GetRepeatedUInt32(m, &f, index) : r.GetUInt32(m, &f));
    case FieldDescriptor::CPPTYPE_UINT64:
      return std::to_string(rep ? r.GetRepeatedUInt64(m, &f, index) : r.GetUInt64(m, &f));
    case FieldDescriptor::CPPTYPE_BOOL:
      return (rep ? r.GetRepeatedBool(m, &f, index) : r.GetBool(m, &f)) ? "true" : "false";
    case FieldDescriptor::CPPTYPE_ENUM:
      return (rep ? r.GetRepeatedEnum(m, &f, index) : r.GetEnum(m, &f))->name();
    case FieldDescriptor::CPPTYPE_STRING:
      return rep ? r.GetRepeatedString(m, &f, index) : r.GetString(m, &f);
    default:
      return "";
  }
}

// One table row per set scalar field, named by its path (the field names carry the datasheet
// units of the job schema, e.g. gyro.arw_deg_per_sqrt_h). Repeated scalars share one row.
void Flatten(const Message& m, const std::string& path, std::string* rows, int depth = 0) {
  if (depth > 16) return;
  const auto& r = *m.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  r.ListFields(m, &fields);
  for (const FieldDescriptor* f : fields) {
    const std::string name = path.empty() ? f->name() : path + "." + f->name();
    if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      if (f->is_repeated()) {
        for (int i = 0; i < r.FieldSize(m, f); ++i) {
          Flatten(r.GetRepeatedMessage(m, f, i), fmt::format("{}[{}]", name, i), rows, depth + 1);
        }
      } else {
        Flatten(r.GetMessage(m, f), name, rows, depth + 1);
      }
      continue;
    }
    std::string value;
    if (f->is_repeated()) {
      for (int i = 0; i < r.FieldSize(m, f); ++i) {
        value += (i ? ", " : "") + ScalarText(m, *f, i);
      }
    } else {
      value = ScalarText(m, *f, -1);
    }
    *rows += "<tr><td><code>" + Escape(name) + "</code></td><td class=\"num\">" + Escape(value) +
             "</td></tr>\n";
  }
}

}  // namespace

std::string PresetSensorJson(const v1::Preset& preset) {
  v1::Job job;
  *job.mutable_sensor() = preset.sensor();
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.preserve_proto_field_names = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(job, &json, print).ok()) return "{}";
  return json;
}

std::string CatalogPage(const Viewer& viewer, const std::vector<v1::PresetSummary>& presets) {
  std::string body =
      "<h1>IMU catalogue</h1>\n<p class=\"note\">The presets a job names with "
      "<code>\"sensor\": {\"preset\": NAME}</code>; each page lists every figure in the job "
      "schema's datasheet units.</p>\n<table class=\"jobs\"><thead><tr><th>Preset</th>"
      "<th>Grade</th><th>Source</th><th>Description</th></tr></thead><tbody>\n";
  for (const v1::PresetSummary& p : presets) {
    body += "<tr><td class=\"name\"><a href=\"/catalog/" + UrlEncode(p.name()) + "\">" +
            Escape(p.name()) + "</a></td><td>" + Escape(p.grade()) + "</td><td>" +
            Escape(p.source()) + "</td><td class=\"description\">" + Escape(p.description()) +
            "</td></tr>\n";
  }
  body += "</tbody></table>\n";
  return Page("IMU catalogue", "catalog", viewer, body);
}

std::string PresetPage(const Viewer& viewer, const v1::Preset& preset) {
  const v1::PresetSummary& s = preset.summary();
  std::string rows;
  Flatten(preset.sensor(), "sensor", &rows);
  std::string body = "<h1>" + Escape(s.name()) +
                     "</h1>\n<table class=\"facts\">\n<tr><th>Grade"
                     "</th><td>" +
                     Escape(s.grade()) + "</td></tr>\n<tr><th>Source</th><td>" +
                     Escape(s.source()) + "</td></tr>\n</table>\n<p class=\"description\">" +
                     Escape(s.description()) + "</p>\n";
  body += "<p class=\"actions\"><a class=\"button\" href=\"/catalog/" + UrlEncode(s.name()) +
          "/sensor.json\" download>Download as a job's sensor section (JSON)</a></p>\n";
  body +=
      "<h2>Figures (datasheet units)</h2>\n<table class=\"params\"><thead><tr><th>Field"
      "</th><th>Value</th></tr></thead><tbody>\n" +
      rows + "</tbody></table>\n";
  body += "<section class=\"commands\"><h2>From the command line</h2>\n" +
          Command("driftlab presets " + s.name()) + "</section>\n";
  return Page(s.name(), "catalog", viewer, body);
}

}  // namespace driftlab::server::web
