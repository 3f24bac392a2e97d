// The report's "What was simulated" table names every aid the job configures, with the values
// the job sets for it (read from the job's aiding section by reflection: an aid added to the
// schema appears without a line of report code).
#include <gtest/gtest.h>

#include <string>

#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "support/report_html.h"
#include "support/test_common.h"

namespace driftlab::app {
namespace {

TEST(HtmlReportSetup, AidingRowNamesEachAidWithTheValuesTheJobSets) {
  v1::JobResult result = ReadJobResult(kCliData / "gate_baseline.json");
  v1::Aiding* aiding = result.mutable_job()->mutable_aiding();
  aiding->Clear();
  aiding->mutable_gnss()->set_rate_hz(2.0);
  aiding->mutable_gnss()->add_outages()->set_start_s(1.0);
  aiding->mutable_barometer()->set_noise_sigma_m(0.5);
  aiding->mutable_magnetometer()->set_rate_hz(50.0);
  v1::OdometerAiding* odometer = aiding->mutable_odometer();
  odometer->set_rate_hz(10.0);
  odometer->set_scale_factor_sigma_ppm(2000.0);
  odometer->add_lever_arm_b_m(0.0);
  odometer->add_lever_arm_b_m(0.0);
  odometer->add_lever_arm_b_m(0.3);
  odometer->set_non_holonomic(true);
  const std::string markup = ::driftlab::testing::WithoutScriptText(RenderHtmlReport(result));
  EXPECT_NE(markup.find("GNSS at 2 Hz, 1 outage(s)"), std::string::npos);
  EXPECT_NE(markup.find("barometer (noise_sigma_m 0.5)"), std::string::npos);
  EXPECT_NE(markup.find("magnetometer (rate_hz 50)"), std::string::npos);
  EXPECT_NE(markup.find("odometer (rate_hz 10, scale_factor_sigma_ppm 2000, lever_arm_b_m [0, 0, "
                        "0.3], non_holonomic true)"),
            std::string::npos);
  // An aid the job leaves out is not named.
  EXPECT_EQ(markup.find("ZUPT"), std::string::npos);
}

}  // namespace
}  // namespace driftlab::app
