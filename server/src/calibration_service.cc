// Calibration service: multi-position / reference calibration and the Allan-deviation noise-model
// fit of streamed samples, and datasheet conversion. The service only assembles the request into
// the library's inputs (app::NumericTable and settings, calibration_job.h; calib/datasheet.h)
// and maps errors to status codes; the fits are the ones `driftlab calibrate`, `driftlab allan
// --fit` and `driftlab datasheet` run.
//
// Stream protocol (Calibrate, FitNoiseModel): the first message carries the settings, exactly
// once; then any number of SampleRows whose values are whole rows of the settings' columns. Every
// value must be finite; the total number of rows is bounded by ServerLimits::max_job_samples
// (RESOURCE_EXHAUSTED beyond). Errors name the message ("rows[3].values[17]") or the settings
// field ("settings.rate_hz"): a library error about a settings field is reported with the
// "settings." prefix, so the path is the request's proto path.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/app/calibration_job.h"
#include "driftlab/app/sensor_model_json.h"
#include "driftlab/calib/datasheet.h"
#include "driftlab/server/data_services.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

// INVALID_ARGUMENT for a library SpecError: fields of the settings message get "settings.".
grpc::Status SettingsError(const SpecError& e, const google::protobuf::Descriptor* settings) {
  const std::string& field = e.field();
  const std::string head = field.substr(0, field.find_first_of(".["));
  if (!head.empty() && settings->FindFieldByName(head) != nullptr) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, std::string("settings.") + e.what());
  }
  return InvalidArgument(e);
}

// The streamed table's column names: as many, as long and as distinct as a CSV header may be
// (calibration_job.h: kMaxCsvColumns, kMaxCsvColumnNameBytes, no repeated name).
void CheckColumnNames(const google::protobuf::RepeatedPtrField<std::string>& names) {
  if (static_cast<size_t>(names.size()) > app::kMaxCsvColumns) {
    throw SpecError("settings.columns", fmt::format("{} columns", names.size()),
                    fmt::format("at most {} columns", app::kMaxCsvColumns));
  }
  for (int i = 0; i < names.size(); ++i) {
    if (names[i].size() > app::kMaxCsvColumnNameBytes) {
      throw SpecError(fmt::format("settings.columns[{}]", i),
                      fmt::format("{} bytes", names[i].size()),
                      fmt::format("at most {} bytes", app::kMaxCsvColumnNameBytes));
    }
    for (int j = 0; j < i; ++j) {
      if (names[i] == names[j]) {
        throw SpecError(fmt::format("settings.columns[{}]", i),
                        "'" + names[i] + fmt::format("' (also columns[{}])", j),
                        "distinct column names");
      }
    }
  }
}

// Reads the settings message and then the rows of a client stream into `table`. `Request` is
// CalibrateRequest or FitNoiseModelRequest (oneof payload {settings, rows}). Returns OK or the
// status to answer with; `settings` holds the first message's settings.
template <typename Request, typename Settings>
grpc::Status ReadStream(grpc::ServerReader<Request>* reader, const ServerLimits& limits,
                        size_t (*column_count)(const Settings&), Settings* settings,
                        app::NumericTable* table) {
  Request request;
  bool have_settings = false;
  size_t columns = 0;
  uint64_t message = 0;       // index in the stream
  uint64_t rows_message = 0;  // index among the rows messages
  while (reader->Read(&request)) {
    if (request.has_settings()) {
      if (have_settings) {
        throw SpecError("settings", fmt::format("a second settings message (message {})", message),
                        "exactly one settings message, the first of the stream");
      }
      have_settings = true;
      *settings = std::move(*request.mutable_settings());
      columns = column_count(*settings);
      if (columns == 0) {
        throw SpecError("settings.columns", "", "the column names of the rows (at least one)");
      }
      CheckColumnNames(settings->columns());
    } else if (request.has_rows()) {
      if (!have_settings) {
        throw SpecError("settings", fmt::format("missing before the rows of message {}", message),
                        "the settings as the first message, then rows");
      }
      const auto& values = request.rows().values();
      if (values.size() % columns != 0) {
        throw SpecError(fmt::format("rows[{}].values", rows_message),
                        fmt::format("{} values", values.size()),
                        fmt::format("a multiple of the {} columns (whole rows)", columns));
      }
      for (int i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i])) {
          const size_t row = table->values.size() / columns + static_cast<size_t>(i) / columns;
          throw SpecError(fmt::format("rows[{}].values[{}]", rows_message, i), ValueText(values[i]),
                          fmt::format("a finite number (row {}, column {})", row,
                                      static_cast<size_t>(i) % columns));
        }
      }
      // Bounded before the values are kept: the upload's memory is at most 8 x max_upload_values.
      const uint64_t total = table->values.size() + static_cast<uint64_t>(values.size());
      if (total > limits.max_upload_values) {
        return grpc::Status(
            grpc::StatusCode::RESOURCE_EXHAUSTED,
            fmt::format("rows: more than {} values (rows x {} columns) in one upload; the "
                        "server's limit is {} (--max-upload-values)",
                        limits.max_upload_values, columns, limits.max_upload_values));
      }
      table->values.insert(table->values.end(), values.begin(), values.end());
      ++rows_message;
    } else {
      throw SpecError("payload", fmt::format("an empty message (message {})", message),
                      "settings (first message) or rows");
    }
    ++message;
  }
  if (!have_settings) throw SpecError("settings", "", "the settings as the first message");
  return grpc::Status::OK;
}

size_t CalibrateColumns(const v1::CalibrateSettings& s) {
  return static_cast<size_t>(s.columns_size());
}
size_t NoiseFitColumns(const v1::NoiseFitSettings& s) {
  return static_cast<size_t>(s.columns_size());
}

app::CalibrateSettings ToCalibrateSettings(const v1::CalibrateSettings& in) {
  app::CalibrateSettings out;
  out.kind = in.kind();
  if (in.has_rate_hz()) {
    if (!std::isfinite(in.rate_hz()) || in.rate_hz() <= 0.0) {
      throw SpecError("settings.rate_hz", ValueText(in.rate_hz()),
                      "a finite rate > 0 Hz (or absent when the columns have t_s)");
    }
    out.rate_hz = in.rate_hz();
  }
  out.lat_deg = in.lat_deg();
  out.height_m = in.height_m();
  if (in.has_init_static_s()) out.init_static_s = in.init_static_s();
  if (in.has_window_s()) out.window_s = in.window_s();
  if (in.has_min_pose_s()) out.min_pose_s = in.min_pose_s();
  if (!in.loss().empty()) out.loss = in.loss();
  out.matrix = in.matrix();
  if (!in.input_unit().empty()) out.input_unit = in.input_unit();
  if (!in.output_unit().empty()) out.output_unit = in.output_unit();
  out.data_name = in.data_name();
  return out;
}

app::NoiseFitSettings ToNoiseFitSettings(const v1::NoiseFitSettings& in) {
  app::NoiseFitSettings out;
  if (!std::isfinite(in.rate_hz()) || in.rate_hz() <= 0.0) {
    throw SpecError("settings.rate_hz", ValueText(in.rate_hz()), "a finite sample rate > 0 Hz");
  }
  out.rate_hz = in.rate_hz();
  // settings.columns name the streamed table's columns; the fit selects among them as `allan
  // --fit` does without --columns (imu.csv's point samples when present, else every column but a
  // time column such as t_s), so a client may stream its time column along.
  if (!in.bias_model().empty()) out.bias_model = in.bias_model();
  if (in.has_points_per_octave()) {
    if (in.points_per_octave() < 1 || in.points_per_octave() > INT_MAX) {
      throw SpecError("settings.points_per_octave", std::to_string(in.points_per_octave()),
                      ">= 1 (default 1)");
    }
    out.points_per_octave = static_cast<int>(in.points_per_octave());
  }
  if (in.has_flicker_tau_min_s()) out.flicker_tau_min_s = in.flicker_tau_min_s();
  if (in.has_flicker_tau_max_s()) out.flicker_tau_max_s = in.flicker_tau_max_s();
  out.datasheet_yaml = in.datasheet_yaml();
  return out;
}

double UnixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The stored name of a call: bounded, as it is the caller's text.
constexpr size_t kMaxRecordNameBytes = 256;

// Records a call that returned a result (data_services.h); logs instead of failing the call.
void Record(JobStore* store, const std::string& owner, const std::string& kind, std::string name,
            const google::protobuf::Message& settings, const google::protobuf::Message& result,
            uint64_t rows, std::chrono::steady_clock::time_point started) {
  if (store == nullptr) return;
  StoredCalibration record;
  try {
    record.id = NewStoreId("cal-");
    record.owner = owner;
    record.kind = kind;
    if (name.size() > kMaxRecordNameBytes) name.resize(kMaxRecordNameBytes);
    record.name = std::move(name);
    record.settings = SerializeDeterministic(settings);
    record.result = SerializeDeterministic(result);
    record.rows = rows;
    record.created_unix_s = UnixNow();
    record.elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    store->InsertCalibration(&record);
    spdlog::info("calibration={} owner={} kind={} rows={}", record.id, owner, kind, rows);
  } catch (const std::exception& e) {
    spdlog::warn("calibration of owner={} not recorded: {}", owner,
                 MessageText(e.what(), kMaxMessageTextBytes));
  }
}

class CalibrationService final : public v1::Calibration::Service {
 public:
  CalibrationService(const Authenticator* auth, const ServerLimits& limits, JobStore* store)
      : auth_(auth), limits_(limits), store_(store) {}

  grpc::Status Calibrate(grpc::ServerContext* context,
                         grpc::ServerReader<v1::CalibrateRequest>* reader,
                         v1::CalibrationResult* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    const auto started = std::chrono::steady_clock::now();
    v1::CalibrateSettings settings;
    app::NumericTable table;
    try {
      const grpc::Status read = ReadStream(reader, limits_, &CalibrateColumns, &settings, &table);
      if (!read.ok()) return read;
      if (context->IsCancelled()) return grpc::Status::CANCELLED;
      table.columns.assign(settings.columns().begin(), settings.columns().end());
      *response = app::RunCalibration(ToCalibrateSettings(settings), table);
    } catch (const SpecError& e) {
      return SettingsError(e, v1::CalibrateSettings::descriptor());
    }
    Record(store_, owner, "calibrate", settings.data_name(), settings, *response, table.rows(),
           started);
    return grpc::Status::OK;
  }

  grpc::Status FitNoiseModel(grpc::ServerContext* context,
                             grpc::ServerReader<v1::FitNoiseModelRequest>* reader,
                             v1::NoiseModelFit* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    const auto started = std::chrono::steady_clock::now();
    v1::NoiseFitSettings settings;
    app::NumericTable table;
    try {
      const grpc::Status read = ReadStream(reader, limits_, &NoiseFitColumns, &settings, &table);
      if (!read.ok()) return read;
      if (context->IsCancelled()) return grpc::Status::CANCELLED;
      table.columns.assign(settings.columns().begin(), settings.columns().end());
      *response = app::RunNoiseFit(ToNoiseFitSettings(settings), table);
    } catch (const SpecError& e) {
      return SettingsError(e, v1::NoiseFitSettings::descriptor());
    }
    Record(store_, owner, "noise_fit", fmt::format("{}", fmt::join(settings.columns(), ", ")),
           settings, *response, table.rows(), started);
    return grpc::Status::OK;
  }

  grpc::Status ConvertDatasheet(grpc::ServerContext* context,
                                const v1::ConvertDatasheetRequest* request,
                                v1::ConvertDatasheetResponse* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    try {
      const calib::DatasheetModel d =
          calib::DatasheetToModel(calib::ParseDatasheetText(request->yaml(), "yaml"));
      *response->mutable_sensor() = app::ToSensorModelProto(d.model);
      for (const calib::DatasheetValue& v : d.values) {
        v1::DatasheetFigure* figure = response->add_figures();
        figure->set_name(v.key);
        figure->set_as_printed(v.text);
        figure->set_value_si(v.value_si);
        figure->set_si_unit(v.si_unit);
        response->add_messages(fmt::format("{} = {} -> {} = {:.6g} {}", v.key, v.text, v.field,
                                           v.value_si, v.si_unit));
      }
    } catch (const SpecError& e) {
      return InvalidArgument(e);
    }
    return grpc::Status::OK;
  }

 private:
  const Authenticator* auth_;
  const ServerLimits limits_;
  JobStore* store_;
};

}  // namespace

std::unique_ptr<v1::Calibration::Service> MakeCalibrationService(const Authenticator* auth,
                                                                 const ServerLimits& limits,
                                                                 JobStore* store) {
  return std::make_unique<CalibrationService>(auth, limits, store);
}

}  // namespace driftlab::server
