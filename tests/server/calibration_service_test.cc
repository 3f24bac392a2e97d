// Calibration service over gRPC (in-process server on 127.0.0.1:0): streamed calibration and
// noise-model fits equal the library calls on the same table, datasheet conversion to SI, and the
// stream protocol's errors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/app/calibration_job.h"
#include "driftlab/random.h"
#include "driftlab/server/data_services.h"
#include "in_process_server.h"
#include "support/accel_tumble.h"

namespace driftlab {
namespace {

using testing::InProcessServer;
using testing::TestAuthenticator;

// Seed 003's turntable data (tests/cli/data/calib_seed003_gyro.csv): ADXRS300 volts at -198, 0,
// +198 deg/s on three axes.
const std::vector<std::string> kReferenceColumns = {"in_x",  "in_y",  "in_z",
                                                    "out_x", "out_y", "out_z"};
const std::vector<double> kReferenceRows = {-198, -198, -198, 1.51, 1.36, 1.38,  //
                                            0,    0,    0,    2.47, 2.45, 2.45,  //
                                            198,  198,  198,  3.52, 3.39, 3.37};

v1::CalibrateRequest Settings(const v1::CalibrateSettings& settings) {
  v1::CalibrateRequest r;
  *r.mutable_settings() = settings;
  return r;
}

v1::CalibrateRequest Rows(const std::vector<double>& values, size_t begin, size_t end) {
  v1::CalibrateRequest r;
  for (size_t i = begin; i < end; ++i) r.mutable_rows()->add_values(values[i]);
  return r;
}

v1::CalibrateSettings ReferenceSettings() {
  v1::CalibrateSettings s;
  s.set_kind("reference");
  s.set_input_unit("deg/s");
  s.set_output_unit("V");
  s.set_data_name("seed003");
  for (const std::string& c : kReferenceColumns) s.add_columns(c);
  return s;
}

class CalibrationServiceTest : public ::testing::Test {
 protected:
  // Sends `requests` on one Calibrate stream.
  grpc::Status Calibrate(const std::vector<v1::CalibrateRequest>& requests,
                         v1::CalibrationResult* result) {
    grpc::ClientContext context;
    auto writer = stub_->Calibrate(&context, result);
    for (const auto& r : requests) {
      if (!writer->Write(r)) break;
    }
    writer->WritesDone();
    return writer->Finish();
  }
  grpc::Status FitNoise(const std::vector<v1::FitNoiseModelRequest>& requests,
                        v1::NoiseModelFit* result) {
    grpc::ClientContext context;
    auto writer = stub_->FitNoiseModel(&context, result);
    for (const auto& r : requests) {
      if (!writer->Write(r)) break;
    }
    writer->WritesDone();
    return writer->Finish();
  }

  TestAuthenticator accept_{true};
  server::ServerLimits limits_;
  std::unique_ptr<v1::Calibration::Service> service_ =
      server::MakeCalibrationService(&accept_, limits_);
  InProcessServer server_{{service_.get()}};
  std::unique_ptr<v1::Calibration::Stub> stub_ = v1::Calibration::NewStub(server_.channel());
};

TEST_F(CalibrationServiceTest, StreamedSeed003CalibrationEqualsTheLibraryCall) {
  v1::CalibrationResult streamed;
  // Settings, then the rows split over two messages (1 row, 2 rows).
  const grpc::Status status = Calibrate(
      {Settings(ReferenceSettings()), Rows(kReferenceRows, 0, 6), Rows(kReferenceRows, 6, 18)},
      &streamed);
  ASSERT_TRUE(status.ok()) << status.error_message();

  app::CalibrateSettings settings;
  settings.kind = "reference";
  settings.input_unit = "deg/s";
  settings.output_unit = "V";
  settings.data_name = "seed003";
  const app::NumericTable table{kReferenceColumns, kReferenceRows};
  v1::CalibrationResult direct = app::RunCalibration(settings, table);
  // Same inputs, same code path: identical bytes (NaN uncertainties included) but the fit times.
  for (auto* result : {&streamed, &direct}) {
    for (auto& fit : *result->mutable_fits()) fit.clear_fit_time_s();
  }
  EXPECT_EQ(streamed.SerializeAsString(), direct.SerializeAsString());

  // Physics: the three points of each axis lie on a line through 2.01 V over 396 deg/s (x) with
  // the null at the mean 2.50 V; least squares is exact to rounding (reference_calibration_test).
  bool found = false;
  for (const auto& fit : streamed.fits()) {
    for (const auto& p : fit.parameters()) {
      if (p.name() == "x.sensitivity") {
        EXPECT_NEAR(p.value(), 2.01 / 396.0, 1e-12);
        found = true;
      }
    }
  }
  EXPECT_TRUE(found) << streamed.DebugString();
}

// White gyro noise of density N = sigma sqrt(dt): 10 min at 100 Hz, fitted with the default model.
TEST_F(CalibrationServiceTest, StreamedNoiseFitEqualsTheLibraryAndRecoversTheWhiteNoise) {
  constexpr double kRate_hz = 100.0;
  constexpr double kN_rad_per_sqrt_s = 1e-3;  // 3.44 deg/sqrt(h)
  constexpr int kSamples = 60000;
  const double sigma = kN_rad_per_sqrt_s * std::sqrt(kRate_hz);
  const RandomStream stream(17, 0, StreamKey{});
  std::vector<double> values(kSamples);
  for (int i = 0; i < kSamples; ++i) values[static_cast<size_t>(i)] = sigma * stream.Gaussian(i);

  v1::FitNoiseModelRequest first;
  first.mutable_settings()->set_rate_hz(kRate_hz);
  first.mutable_settings()->add_columns("omega_x_rad_per_s");
  std::vector<v1::FitNoiseModelRequest> requests = {first};
  for (int begin = 0; begin < kSamples; begin += 25000) {  // three messages
    v1::FitNoiseModelRequest r;
    for (int i = begin; i < std::min(kSamples, begin + 25000); ++i) {
      r.mutable_rows()->add_values(values[static_cast<size_t>(i)]);
    }
    requests.push_back(r);
  }
  v1::NoiseModelFit streamed;
  const grpc::Status status = FitNoise(requests, &streamed);
  ASSERT_TRUE(status.ok()) << status.error_message();

  app::NoiseFitSettings settings;
  settings.rate_hz = kRate_hz;
  settings.columns = {"omega_x_rad_per_s"};
  v1::NoiseModelFit direct = app::RunNoiseFit(settings, {{"omega_x_rad_per_s"}, values});
  streamed.clear_fit_time_s();
  direct.clear_fit_time_s();
  EXPECT_EQ(streamed.SerializeAsString(), direct.SerializeAsString());

  int white_terms = 0;
  for (const v1::NoiseTerm& t : streamed.terms()) {
    if (t.triad() != "gyro" || t.name() != "white_noise") continue;
    ++white_terms;
    // The fit's own 1-sigma (Ceres covariance of the Allan-curve fit); 4 sigma: a seeded draw
    // outside it would be a 6e-5 event.
    EXPECT_GT(t.sigma(), 0.0);
    EXPECT_LT(t.sigma(), 0.05 * kN_rad_per_sqrt_s);
    EXPECT_NEAR(t.value(), kN_rad_per_sqrt_s, 4.0 * t.sigma()) << t.axis();
    std::printf("white noise (%s): %.6g +- %.3g rad/sqrt(s), true %.6g\n", t.axis().c_str(),
                t.value(), t.sigma(), kN_rad_per_sqrt_s);
  }
  EXPECT_GE(white_terms, 1) << streamed.DebugString();
}

TEST_F(CalibrationServiceTest, DatasheetFiguresConvertToSi) {
  v1::ConvertDatasheetRequest request;
  request.set_yaml(
      "name: test-imu\n"
      "gyro: {arw: \"0.15 deg/√h\", bias_instability: \"0.5 deg/h\"}\n"
      "accel: {vrw: \"0.06 m/s/√h\"}\n");
  v1::ConvertDatasheetResponse response;
  grpc::ClientContext context;
  const grpc::Status status = stub_->ConvertDatasheet(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.figures_size(), 3);
  // 1 deg/sqrt(h) = (pi / 180) rad / sqrt(3600 s) = (pi / 180) / 60 rad/sqrt(s);
  // 1 deg/h = (pi / 180) / 3600 rad/s; 1 m/s/sqrt(h) = 1 / 60 m/s/sqrt(s) (SEEDS.md seed 001
  // units). Products of a few rounded factors: 1e-15 relative allows 4 roundings.
  const double expected[3] = {0.15 * M_PI / 180.0 / 60.0, 0.5 * M_PI / 180.0 / 3600.0, 0.06 / 60.0};
  const char* names[3] = {"gyro.arw", "gyro.bias_instability", "accel.vrw"};
  const char* units[3] = {"rad/sqrt(s)", "rad/s", "m/s/sqrt(s)"};
  for (int i = 0; i < 3; ++i) {
    const v1::DatasheetFigure& f = response.figures(i);
    EXPECT_EQ(f.name(), names[i]);
    EXPECT_EQ(f.si_unit(), units[i]);
    EXPECT_NEAR(f.value_si(), expected[i], 1e-15 * expected[i]) << f.name();
  }
  EXPECT_EQ(response.figures(0).as_printed(), "0.15 deg/√h");
  // The job-schema model carries the figures back in datasheet units (round trip ~1e-15).
  EXPECT_NEAR(response.sensor().gyro().arw_deg_per_sqrt_h(), 0.15, 1e-14);
  EXPECT_NEAR(response.sensor().gyro().bias_instability_deg_per_h(), 0.5, 1e-14);
}

TEST_F(CalibrationServiceTest, MalformedStreamsAreInvalidArgumentNamingTheField) {
  struct Case {
    const char* what;
    std::vector<v1::CalibrateRequest> requests;
    const char* field;
  };
  v1::CalibrateSettings negative_rate = ReferenceSettings();
  negative_rate.set_rate_hz(-100.0);
  v1::CalibrateSettings unknown_kind = ReferenceSettings();
  unknown_kind.set_kind("magnetometer");
  // Unknown units, a unit of the wrong dimension and duplicate columns are refused too.
  v1::CalibrateSettings unknown_unit = ReferenceSettings();
  unknown_unit.set_input_unit("furlong/fortnight");
  v1::CalibrateSettings wrong_dimension = ReferenceSettings();
  wrong_dimension.set_input_unit("m");  // a length: neither a rate nor an acceleration
  v1::CalibrateSettings duplicate_column = ReferenceSettings();
  duplicate_column.set_columns(1, duplicate_column.columns(0));
  std::vector<double> with_nan = kReferenceRows;
  with_nan[4] = NAN;
  const std::vector<Case> cases = {
      {"rows before settings",
       {Rows(kReferenceRows, 0, 6), Settings(ReferenceSettings())},
       "settings: missing before the rows of message 0"},
      {"settings twice",
       {Settings(ReferenceSettings()), Rows(kReferenceRows, 0, 6), Settings(ReferenceSettings())},
       "settings: a second settings message"},
      {"row length",
       {Settings(ReferenceSettings()), Rows(kReferenceRows, 0, 7)},
       "rows[0].values: 7 values"},
      {"NaN", {Settings(ReferenceSettings()), Rows(with_nan, 0, 18)}, "rows[0].values[4]: nan"},
      {"negative rate",
       {Settings(negative_rate), Rows(kReferenceRows, 0, 18)},
       "settings.rate_hz: -100"},
      {"unknown kind (library error)",
       {Settings(unknown_kind), Rows(kReferenceRows, 0, 18)},
       "settings.kind"},
      {"no settings at all", {}, "settings: missing"},
      {"unknown input unit",
       {Settings(unknown_unit), Rows(kReferenceRows, 0, 18)},
       "settings.input_unit"},
      {"input unit of the wrong dimension",
       {Settings(wrong_dimension), Rows(kReferenceRows, 0, 18)},
       "settings.input_unit"},
      {"duplicate column",
       {Settings(duplicate_column), Rows(kReferenceRows, 0, 18)},
       "settings.columns[1]"},
  };
  for (const Case& c : cases) {
    v1::CalibrationResult result;
    const grpc::Status status = Calibrate(c.requests, &result);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.what;
    EXPECT_EQ(status.error_message().rfind(c.field, 0), 0u)
        << c.what << ": " << status.error_message();
  }

  v1::FitNoiseModelRequest bad_rate;
  bad_rate.mutable_settings()->set_rate_hz(-1.0);
  bad_rate.mutable_settings()->add_columns("omega_x_rad_per_s");
  v1::FitNoiseModelRequest rows;
  for (int i = 0; i < 100; ++i) rows.mutable_rows()->add_values(0.01 * i);
  v1::NoiseModelFit fit;
  const grpc::Status status = FitNoise({bad_rate, rows}, &fit);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(status.error_message().rfind("settings.rate_hz: -1", 0), 0u) << status.error_message();
}

// A recording clipped below 1 g (a saturated accelerometer) is refused as through the CLI, and the
// columns are taken by their names (accelerometer columns first here).
TEST_F(CalibrationServiceTest, ClippedRecordingIsRefusedAndColumnsAreReadByName) {
  const double b[3] = {0.05, -0.08, 0.12};
  v1::CalibrateSettings settings;
  settings.set_kind("accel");
  settings.set_lat_deg(45.0);
  for (const char* c : {"t_s", "ax", "ay", "az", "gx", "gy", "gz"}) settings.add_columns(c);
  const auto rows = [](const std::vector<std::array<double, 7>>& in) {
    v1::CalibrateRequest r;
    for (const auto& row : in) {
      for (const int i : {0, 4, 5, 6, 1, 2, 3}) r.mutable_rows()->add_values(row[i]);
    }
    return r;
  };
  v1::CalibrationResult result;
  // Noise 2 mg, clipped at 0.8 g.
  grpc::Status status = Calibrate(
      {Settings(settings), rows(testing::AccelTumbleRows(b, 0.02, 0.8 * 9.80665))}, &result);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("clipped at "), std::string::npos)
      << status.error_message();
  // Noise-free and not clipped: the bias is recovered to the 6-digit gravity constant.
  status = Calibrate({Settings(settings), rows(testing::AccelTumbleRows(b))}, &result);
  ASSERT_TRUE(status.ok()) << status.error_message();
  bool found = false;
  for (const auto& fit : result.fits()) {
    for (const auto& p : fit.parameters()) {
      if (p.name() == "accel.bias.x") {
        EXPECT_NEAR(p.value(), b[0], 1e-4);
        found = true;
      }
    }
  }
  EXPECT_TRUE(found);
}

TEST_F(CalibrationServiceTest, StreamBeyondTheUploadValueLimitIsResourceExhausted) {
  TestAuthenticator accept(true);
  server::ServerLimits limits;
  limits.max_upload_values = 12;  // two rows of the 6-column reference table
  auto service = server::MakeCalibrationService(&accept, limits);
  InProcessServer server({service.get()});
  auto stub = v1::Calibration::NewStub(server.channel());
  grpc::ClientContext context;
  v1::CalibrationResult result;
  auto writer = stub->Calibrate(&context, &result);
  writer->Write(Settings(ReferenceSettings()));
  writer->Write(Rows(kReferenceRows, 0, 18));  // 3 rows = 18 values > 12
  writer->WritesDone();
  EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
}

TEST(CalibrationServiceAuth, CallWithoutValidTokenIsUnauthenticated) {
  TestAuthenticator reject(false);
  auto service = server::MakeCalibrationService(&reject, server::ServerLimits{});
  InProcessServer server({service.get()});
  auto stub = v1::Calibration::NewStub(server.channel());
  grpc::ClientContext context;
  v1::ConvertDatasheetResponse response;
  EXPECT_EQ(stub->ConvertDatasheet(&context, v1::ConvertDatasheetRequest(), &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
}

}  // namespace
}  // namespace driftlab
