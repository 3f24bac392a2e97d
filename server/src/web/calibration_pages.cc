// The recorded calibrations and noise fits (JobStore::ListCalibrations): list and page.
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>

#include "driftlab/app/calibration_job.h"
#include "driftlab/report/calibration_report.h"
#include "driftlab/spec_error.h"
#include "web/pages.h"

namespace driftlab::server::web {
namespace {

std::string Href(const StoredCalibration& record) {
  return "/calibrations/" + UrlEncode(record.id);
}

std::string KindLabel(const StoredCalibration& record) {
  if (record.kind == "noise_fit") return "noise-model fit";
  v1::CalibrateSettings settings;
  if (settings.ParseFromString(record.settings) && !settings.kind().empty()) {
    return settings.kind() + " calibration";
  }
  return "calibration";
}

std::string Name(const StoredCalibration& record) {
  return record.name.empty() ? "(no data name)" : record.name;
}

std::string Number(double value) {
  if (std::isnan(value)) return "–";
  return fmt::format("{:.6g}", value);
}

std::string PrintJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.preserve_proto_field_names = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(message, &json, print).ok()) return "{}";
  return json;
}

std::string CalibrationFits(const v1::CalibrationResult& result) {
  std::string html;
  if (result.messages_size() > 0) {
    // The first message summarises the static detection; the pose list stays collapsed.
    html += "<p class=\"note\">" + Escape(result.messages(0)) + "</p>\n";
    if (result.messages_size() > 1) {
      html += fmt::format("<details><summary>{} more messages (poses)</summary>\n",
                          result.messages_size() - 1);
      for (int i = 1; i < result.messages_size(); ++i) {
        html += "<p class=\"note\">" + Escape(result.messages(i)) + "</p>\n";
      }
      html += "</details>\n";
    }
  }
  for (const v1::CalibrationFitResult& fit : result.fits()) {
    html += fmt::format(
        "<h3>{} fit</h3>\n<p>Residual RMS {} {} · {} poses or rows · {} iterations</p>\n"
        "<table class=\"params\"><thead><tr><th>Parameter</th><th>Value</th><th>1 σ</th>"
        "<th>Unit</th></tr></thead><tbody>\n",
        Escape(fit.kind()), Number(fit.residual_rms()), Escape(fit.residual_unit()),
        fit.poses_used(), fit.iterations());
    for (const v1::CalibrationParameter& p : fit.parameters()) {
      html += "<tr><td>" + Escape(p.name()) + "</td><td class=\"num\">" + Number(p.value()) +
              "</td><td class=\"num\">" + Number(p.sigma()) + "</td><td>" + Escape(p.unit()) +
              "</td></tr>\n";
    }
    html += "</tbody></table>\n";
  }
  return html;
}

std::string NoiseTerms(const v1::NoiseModelFit& fit) {
  std::string html =
      "<table class=\"params\"><thead><tr><th>Triad</th><th>Axis</th><th>Term</th>"
      "<th>Value</th><th>1 σ</th><th>Unit (SI)</th><th>Determined</th></tr></thead><tbody>\n";
  for (const v1::NoiseTerm& t : fit.terms()) {
    html += "<tr><td>" + Escape(t.triad()) + "</td><td>" + Escape(t.axis()) + "</td><td>" +
            Escape(t.name()) + "</td><td class=\"num\">" + Number(t.value()) +
            "</td><td class=\"num\">" + Number(t.sigma()) + "</td><td>" + Escape(t.unit()) +
            "</td><td>" +
            (t.determined() ? "yes" : "no (upper bound " + Number(t.upper_bound()) + ")") +
            "</td></tr>\n";
  }
  html += "</tbody></table>\n";
  for (const std::string& w : fit.warnings()) {
    html += "<p class=\"warning\">" + Escape(w) + "</p>\n";
  }
  return html;
}

// The `driftlab calibrate` options of the recorded settings.
std::string CalibrateOptions(const v1::CalibrateSettings& s) {
  std::string options = " " + s.kind() + " DATA.csv";
  if (s.has_rate_hz()) options += " --rate " + Number(s.rate_hz());
  if (s.lat_deg() != 0.0) options += " --lat " + fmt::format("{}", s.lat_deg());
  if (s.height_m() != 0.0) options += " --height " + fmt::format("{}", s.height_m());
  if (s.has_init_static_s()) options += fmt::format(" --init-static {}", s.init_static_s());
  if (s.has_window_s()) options += fmt::format(" --window {}", s.window_s());
  if (s.has_min_pose_s()) options += fmt::format(" --min-pose {}", s.min_pose_s());
  if (!s.loss().empty()) options += " --loss " + s.loss();
  if (s.matrix()) options += " --matrix";
  if (!s.input_unit().empty()) options += " --input-unit " + s.input_unit();
  if (!s.output_unit().empty()) options += " --output-unit " + s.output_unit();
  return options;
}

}  // namespace

std::optional<std::string> CalibrationResultJson(const StoredCalibration& record) {
  try {
    if (record.kind == "calibrate") {
      v1::CalibrationResult result;
      if (!result.ParseFromString(record.result)) return std::nullopt;
      return app::CalibrationResultToJson(result);
    }
    v1::NoiseModelFit fit;
    if (!fit.ParseFromString(record.result)) return std::nullopt;
    return app::NoiseModelFitToJson(fit);
  } catch (const SpecError&) {
    return std::nullopt;
  }
}

std::optional<std::string> CalibrationSettingsJson(const StoredCalibration& record) {
  if (record.kind == "calibrate") {
    v1::CalibrateSettings settings;
    if (!settings.ParseFromString(record.settings)) return std::nullopt;
    return PrintJson(settings);
  }
  v1::NoiseFitSettings settings;
  if (!settings.ParseFromString(record.settings)) return std::nullopt;
  return PrintJson(settings);
}

std::optional<std::string> CalibrationReport(const StoredCalibration& record) {
  if (record.kind == "calibrate") {
    v1::CalibrationResult result;
    if (!result.ParseFromString(record.result)) return std::nullopt;
    return app::RenderCalibrationReport(result);
  }
  v1::NoiseModelFit fit;
  if (!fit.ParseFromString(record.result)) return std::nullopt;
  return app::RenderNoiseFitReport(fit, app::NoiseFitTitle(fit));
}

std::string CalibrationListPage(const Viewer& viewer, const std::vector<StoredCalibration>& list) {
  std::string body =
      "<h1>Calibrations</h1>\n<p class=\"note\">Every calibration and noise-model fit this token "
      "ran on the server (<code>driftlab calibrate … --server</code>, gRPC Calibration), newest "
      "first. The uploaded samples are not kept; the results are.</p>\n"
      "<table class=\"jobs\"><thead><tr><th>Data</th><th>Kind</th><th>Time</th><th>Rows</th>"
      "<th>Duration</th></tr></thead><tbody>\n";
  for (const StoredCalibration& r : list) {
    body += fmt::format(
        "<tr><td class=\"name\"><a href=\"{}\">{}</a><div class=\"id\">{}</div></td><td>{}</td>"
        "<td class=\"time\">{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n",
        Href(r), Escape(Name(r)), Escape(r.id), Escape(KindLabel(r)), FormatUtc(r.created_unix_s),
        FormatCount(r.rows), FormatDuration(r.elapsed_s));
  }
  if (list.empty()) {
    body += "<tr><td colspan=\"5\" class=\"empty\">No calibrations yet.</td></tr>\n";
  }
  body += "</tbody></table>\n";
  return Page("Calibrations", "calibrations", viewer, body);
}

std::string CalibrationPage(const Viewer& viewer, const StoredCalibration& record,
                            const GrpcTarget& grpc) {
  const std::optional<std::string> settings_json = CalibrationSettingsJson(record);
  if (!settings_json) return "";
  std::string body = "<h1>" + Escape(Name(record)) + "</h1>\n<p class=\"id\">" + Escape(record.id) +
                     "</p>\n<table class=\"facts\">\n";
  body += "<tr><th>Kind</th><td>" + Escape(KindLabel(record)) + "</td></tr>\n";
  body += "<tr><th>Time</th><td>" + FormatUtc(record.created_unix_s) + "</td></tr>\n";
  body += "<tr><th>Rows uploaded</th><td>" + FormatCount(record.rows) + "</td></tr>\n";
  body += "<tr><th>Duration</th><td>" + FormatDuration(record.elapsed_s) + "</td></tr>\n</table>\n";
  const std::string href = Href(record);
  const std::string file = record.id + ".json";
  body += "<p class=\"actions\"><a class=\"button\" href=\"" + href +
          "/report.html\" target=\"_blank\" rel=\"noopener\">Open the report</a> <a "
          "class=\"button\" href=\"" +
          href + "/result.json\" download>Download the result (JSON)</a></p>\n";
  const std::string remote = " --server " + grpc.address + (grpc.tls ? " --tls-ca CA.pem" : "");
  body += "<section><h2>Result</h2>\n";
  std::string commands;
  if (record.kind == "calibrate") {
    v1::CalibrationResult result;
    v1::CalibrateSettings settings;
    if (!result.ParseFromString(record.result) || !settings.ParseFromString(record.settings)) {
      return "";
    }
    body += CalibrationFits(result);
    commands = "<p>The same report from the result file (" + Escape(file) +
               "; without the recording's plots, which need the samples):</p>\n" +
               Command("driftlab report " + file + " --out report.html") +
               "<p>Run it again with the recording (DATA.csv, the columns " +
               Escape(fmt::format("{}", fmt::join(settings.columns(), ","))) + "):</p>\n" +
               Command("driftlab calibrate" + CalibrateOptions(settings) + remote +
                       " --out calibration.json --report report.html");
  } else {
    v1::NoiseModelFit fit;
    v1::NoiseFitSettings settings;
    if (!fit.ParseFromString(record.result) || !settings.ParseFromString(record.settings)) {
      return "";
    }
    body += NoiseTerms(fit);
    body += "<h3>Fitted sensor model (job schema, datasheet units)</h3>\n" +
            JsonTree(PrintJson(fit.sensor()), 1);
    commands = "<p>The same report from the fit file (" + Escape(file) + "):</p>\n" +
               Command("driftlab report " + file + " --out report.html") +
               "<p>Fit the recording in-process:</p>\n" +
               Command(fmt::format("driftlab allan DATA.csv --rate {} --fit{} --fit-json fit.json "
                                   "--report report.html",
                                   settings.rate_hz(),
                                   settings.bias_model().empty()
                                       ? std::string()
                                       : " --bias-model " + settings.bias_model()));
  }
  body += "</section>\n<section class=\"commands\"><h2>From the command line</h2>\n" + commands +
          "</section>\n<section><h2>Settings</h2>\n<p><a href=\"" + href +
          "/settings.json\" download>Download the settings</a></p>\n" +
          JsonTree(*settings_json, 1) + "</section>\n";
  return Page(Name(record), "calibrations", viewer, body);
}

}  // namespace driftlab::server::web
