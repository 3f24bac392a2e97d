// Catalog service over gRPC (in-process server on 127.0.0.1:0): the engine's presets with their
// grade and source, a preset's sensor model in job-schema units, and the example jobs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/presets.h"
#include "driftlab/server/data_services.h"
#include "in_process_server.h"

namespace driftlab {
namespace {

using testing::InProcessServer;
using testing::TestAuthenticator;

class CatalogServiceTest : public ::testing::Test {
 protected:
  TestAuthenticator accept_{true};
  std::unique_ptr<v1::Catalog::Service> service_ =
      server::MakeCatalogService(&accept_, std::string(DRIFTLAB_SOURCE_DIR) + "/examples");
  InProcessServer server_{{service_.get()}};
  std::unique_ptr<v1::Catalog::Stub> stub_ = v1::Catalog::NewStub(server_.channel());
};

TEST_F(CatalogServiceTest, ListPresetsGivesEveryCatalogueModelWithGradeAndSource) {
  grpc::ClientContext context;
  v1::ListPresetsResponse response;
  ASSERT_TRUE(stub_->ListPresets(&context, v1::ListPresetsRequest(), &response).ok());
  const std::vector<ImuErrorModel>& catalogue = ImuCatalogue();
  ASSERT_EQ(static_cast<size_t>(response.presets_size()), catalogue.size());
  for (size_t i = 0; i < catalogue.size(); ++i) {
    const v1::PresetSummary& p = response.presets(static_cast<int>(i));
    EXPECT_EQ(p.name(), catalogue[i].name);
    EXPECT_EQ(p.description(), catalogue[i].description);
    EXPECT_FALSE(p.grade().empty()) << p.name();
    EXPECT_FALSE(p.source().empty()) << p.name();
  }
  auto find = [&](const std::string& name) {
    return *std::find_if(response.presets().begin(), response.presets().end(),
                         [&](const v1::PresetSummary& p) { return p.name() == name; });
  };
  EXPECT_EQ(find("tactical").grade(), "tactical");
  EXPECT_EQ(find("tactical").source(), "seed 001 grade tables");
  EXPECT_EQ(find("seed002-epson").source(), "seed 002 catalogue");
  EXPECT_EQ(find("adis16470").source(), "ADIS16470 datasheet Rev. C");
  EXPECT_EQ(find("stim300").source(), "STIM300 datasheet TS1524 rev. 31");
  EXPECT_EQ(find("stim300-rev9").source(), "STIM300 datasheet revision 9");
  EXPECT_EQ(find("epson-m-g370pdg0").source(), "M-G370PDG0 datasheet E Rev. 1.1");
  EXPECT_EQ(find("adis16465-1").source(), "ADIS16465 datasheet");
  EXPECT_EQ(find("adis16505-1").source(), "ADIS16505 datasheet");
  EXPECT_EQ(find("hg1700").source(), "HG1700 brochure N61-1619-000-001");
  EXPECT_EQ(find("seed003-adxrs300-adxl330").source(),
            "seed 003; ADXRS300 datasheet Rev. B; ADXL330 datasheet Rev. A");
  // Seed 001 gyro grades (ARW and bias instability must both meet it): STIM300 0.15 deg/sqrt(h)
  // and 0.3 deg/h: tactical (0.3 is in the table's 0.01-1 gap, counted tactical); ADIS16470
  // 0.34 deg/sqrt(h) and 8 deg/h: tactical; BMI088 0.014 (deg/s)/sqrt(Hz) = 0.84 deg/sqrt(h) > 0.5:
  // rate grade.
  EXPECT_EQ(find("stim300").grade(), "tactical");
  EXPECT_EQ(find("adis16470").grade(), "tactical");
  EXPECT_EQ(find("bmi088").grade(), "rate");
}

TEST_F(CatalogServiceTest, GetPresetSensorModelTranslatesBackToTheCatalogueModel) {
  for (const char* name : {"stim300", "tactical", "seed003-adxrs300-adxl330", "hg9900"}) {
    grpc::ClientContext context;
    v1::GetPresetRequest request;
    request.set_name(name);
    v1::Preset preset;
    ASSERT_TRUE(stub_->GetPreset(&context, request, &preset).ok()) << name;
    EXPECT_EQ(preset.summary().name(), name);
    EXPECT_TRUE(preset.sensor().preset().empty()) << "the model must be explicit, not a preset";
    v1::Job job;
    *job.mutable_sensor() = preset.sensor();
    const std::optional<ImuErrorModel> back = app::ToImuErrorModel(job);
    ASSERT_TRUE(back.has_value()) << name;
    const ImuErrorModel& want = FindImuPreset(name);
    // Datasheet units and back through the units module: a few roundings of the SI factors
    // (sensor_model_json.h: ~1e-15 relative); 1e-13 relative leaves room for 100 of them.
    auto near = [](double a, double b) { return std::abs(a - b) <= 1e-13 * std::abs(b); };
    for (const auto& [got, ref] :
         {std::pair{&back->gyro, &want.gyro}, std::pair{&back->accel, &want.accel}}) {
      EXPECT_TRUE(near(got->white_noise_density, ref->white_noise_density)) << name;
      EXPECT_TRUE(near(got->bias_flicker.bias_instability, ref->bias_flicker.bias_instability))
          << name;
      EXPECT_TRUE(near(got->turn_on_bias_sigma, ref->turn_on_bias_sigma)) << name;
      EXPECT_TRUE(near(got->scale_factor_sigma, ref->scale_factor_sigma)) << name;
      EXPECT_TRUE(near(got->misalignment_sigma_rad, ref->misalignment_sigma_rad)) << name;
      EXPECT_TRUE(near(got->random_walk, ref->random_walk)) << name;
      EXPECT_TRUE(near(got->range, ref->range)) << name;
    }
  }
}

TEST_F(CatalogServiceTest, UnknownPresetIsNotFoundAndListsTheNames) {
  grpc::ClientContext context;
  v1::GetPresetRequest request;
  request.set_name("no-such-imu");
  v1::Preset preset;
  const grpc::Status status = stub_->GetPreset(&context, request, &preset);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(status.error_message().find("no-such-imu"), std::string::npos);
  EXPECT_NE(status.error_message().find("stim300"), std::string::npos) << status.error_message();
}

TEST_F(CatalogServiceTest, ListExamplesOffersRunnableJobsWithoutFileReferences) {
  grpc::ClientContext context;
  v1::ListExamplesResponse response;
  ASSERT_TRUE(stub_->ListExamples(&context, v1::ListExamplesRequest(), &response).ok());
  std::vector<std::string> names;
  for (const v1::Example& e : response.examples()) {
    names.push_back(e.name());
    EXPECT_FALSE(e.job().motion().has_gnss_ins_sim_file()) << e.name();
    EXPECT_FALSE(e.job().motion().has_truth_profile_file()) << e.name();
    // Runnable as sent: the server's validation (the CLI's) accepts it.
    EXPECT_NO_THROW(app::ToMonteCarloSpec(app::JobFile{e.job(), ""}, {})) << e.name();
  }
  auto has = [&](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  EXPECT_TRUE(has("car_drive"));
  EXPECT_TRUE(has("static_alignment_navigation"));  // YAML
  EXPECT_FALSE(has("gnss_ins_sim_import"));         // references a motion file
  EXPECT_FALSE(has("truth_profile_import"));
}

TEST(CatalogServiceAuth, CallWithoutValidTokenIsUnauthenticated) {
  TestAuthenticator reject(false);
  auto service =
      server::MakeCatalogService(&reject, std::string(DRIFTLAB_SOURCE_DIR) + "/examples");
  InProcessServer server({service.get()});
  auto stub = v1::Catalog::NewStub(server.channel());
  grpc::ClientContext context;
  v1::ListPresetsResponse response;
  EXPECT_EQ(stub->ListPresets(&context, v1::ListPresetsRequest(), &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
}

}  // namespace
}  // namespace driftlab
