// In-process tests of the calibration and noise-fit cores (app/calibration_job.h) and their
// HTML reports (report/calibration_report.h), plus one run of the `driftlab` binary to show that
// `driftlab calibrate` writes exactly what RunCalibration returns for the same CSV.
#include "driftlab/report/calibration_report.h"

#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "driftlab/app/calibration_job.h"
#include "driftlab/calib/tumble.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"
#include "support/cli_runner.h"
#include "support/report_html.h"
#include "support/spec_errors.h"

namespace driftlab::app {
namespace {

namespace fs = std::filesystem;
using ::driftlab::testing::RunDriftlab;
using ::driftlab::testing::Scratch;

using testing::Count;

// Every opened element is closed in order (void elements and "/>" excepted): returns "" or the
// first mismatch.
std::string TagBalance(const std::string& page) {
  const std::string html = ::driftlab::testing::WithoutScriptText(page);
  std::vector<std::string> stack;
  for (size_t at = html.find('<'); at != std::string::npos; at = html.find('<', at + 1)) {
    const size_t end = html.find('>', at);
    if (end == std::string::npos) return "unterminated tag";
    const std::string tag = html.substr(at + 1, end - at - 1);
    if (tag.empty() || tag[0] == '!') continue;
    const bool closing = tag[0] == '/';
    const std::string name =
        tag.substr(closing ? 1 : 0, tag.find_first_of(" />", closing ? 1 : 0) - (closing ? 1 : 0));
    if (tag.back() == '/' || name == "meta" || name == "br") continue;
    if (!closing) {
      stack.push_back(name);
    } else if (stack.empty() || stack.back() != name) {
      return "</" + name + "> closes <" + (stack.empty() ? "" : stack.back()) + ">";
    } else {
      stack.pop_back();
    }
  }
  return stack.empty() ? "" : "<" + stack.back() + "> not closed";
}

// Every number in the script of the plot with element id `id` (its data, exact: the report
// writes the shortest text that reads back as the same double).
std::vector<double> PlotNumbers(const std::string& html, const std::string& id) {
  std::vector<double> out;
  const size_t start = html.find("<script>driftlabPlot(\"" + id + "\"");
  if (start == std::string::npos) return out;
  const size_t end = html.find("</script>", start);
  const size_t data = html.find("\"data\":", start);
  for (size_t at = data; at < end; ++at) {
    const char c = html[at];
    if ((c >= '0' && c <= '9') || c == '-') {
      char* stop = nullptr;
      out.push_back(std::strtod(html.c_str() + at, &stop));
      at = static_cast<size_t>(stop - html.c_str());
    }
  }
  return out;
}

// The data-value numbers of the cells of the table row whose first cell is `name`.
std::vector<double> RowValues(const std::string& html, const std::string& name) {
  std::vector<double> out;
  const size_t row = html.find("<tr><td>" + name + "</td>");
  if (row == std::string::npos) return out;
  const size_t row_end = html.find("</tr>", row);
  for (size_t at = html.find("data-value=\"", row); at < row_end;
       at = html.find("data-value=\"", at + 1)) {
    out.push_back(std::stod(html.substr(at + 12)));
  }
  return out;
}

// A 19-pose tumble (TumbleSpec defaults: 30 s initial pose, 5 s poses, 1 s rotations, 100 Hz) of
// the tactical preset without in-run bias variation (what the Allan fit, not this one, models).
calib::Tumble TacticalTumble() {
  ImuErrorModel model = FindImuPreset("tactical");
  model.gyro_g_sensitivity.setZero();
  for (TriadErrorParams* t : {&model.gyro, &model.accel}) {
    t->bias_flicker.bias_instability = 0.0;
    t->bias_gauss_markov = {};
    t->random_walk = 0.0;
  }
  calib::TumbleSpec spec;
  spec.earth_rate = false;
  return calib::SimulateTumble(spec, model, 7, 0);
}

NumericTable ToTable(const calib::RawImuRecording& rec) {
  NumericTable table;
  table.columns = {"t_s", "gx", "gy", "gz", "ax", "ay", "az"};
  for (size_t k = 0; k < rec.size(); ++k) {
    table.values.push_back(rec.t_s[k]);
    for (int i = 0; i < 3; ++i) table.values.push_back(rec.omega_ib_s[k][i]);
    for (int i = 0; i < 3; ++i) table.values.push_back(rec.f_ib_s[k][i]);
  }
  return table;
}

CalibrateSettings ImuSettings() {
  CalibrateSettings s;
  s.kind = "imu";
  s.lat_deg = 45.0;  // TumbleSpec default lat_rad = pi / 4
  s.data_name = "tumble";
  return s;
}

TEST(CalibrationReport, ShowsEveryParameterResidualCorrelationAndZeroFlag) {
  const calib::Tumble tumble = TacticalTumble();
  const v1::CalibrationResult result = RunCalibration(ImuSettings(), ToTable(tumble.recording));
  ASSERT_EQ(result.fits_size(), 2);
  const v1::CalibrationFitResult& accel = result.fits(0);
  const v1::CalibrationFitResult& gyro = result.fits(1);
  // 19 poses simulated; the accel fit has one |f| - g residual per pose, the gyro fit two per
  // rotation between consecutive poses (18 rotations, all > 1 deg: 80..150 deg by construction).
  EXPECT_EQ(accel.poses_used(), 19);
  EXPECT_EQ(accel.residuals_size(), 19);
  EXPECT_EQ(gyro.residuals_size(), 2 * 18);

  const std::string html = RenderCalibrationReport(result);
  EXPECT_EQ(TagBalance(html), "");
  EXPECT_EQ(html.substr(0, 15), "<!DOCTYPE html>");
  const std::string markup = ::driftlab::testing::WithoutScriptText(html);
  for (const char* external : {"http://", "https://", "src="}) {
    EXPECT_EQ(markup.find(external), std::string::npos) << external;
  }
  // One interactive residual plot per fit, holding every residual (shortest
  // round-trip text of the double), and the pose-direction map of the 19 poses.
  EXPECT_EQ(Count(html, "id=\"plot-residuals-"), 2u);
  for (const v1::CalibrationFitResult& fit : result.fits()) {
    const std::vector<double> plotted = PlotNumbers(html, "plot-residuals-" + fit.kind());
    for (const double r : fit.residuals()) {
      EXPECT_NE(std::find(plotted.begin(), plotted.end(), r), plotted.end()) << fit.kind() << r;
    }
  }
  EXPECT_EQ(Count(html, "id=\"plot-pose-directions\""), 1u);
  // The model equation and the datasheet units beside SI.
  EXPECT_NE(html.find("Sign convention"), std::string::npos);
  EXPECT_NE(html.find(" ppm +- "), std::string::npos);
  EXPECT_NE(html.find(" mrad +- "), std::string::npos);
  EXPECT_NE(html.find(" mg +- "), std::string::npos);
  EXPECT_NE(html.find(" deg/h +- "), std::string::npos);
  // Correlation matrices: every fit carries one (n x n, unit diagonal, |rho| <= 1).
  for (const v1::CalibrationFitResult& fit : result.fits()) {
    const int n = fit.parameters_size();
    ASSERT_EQ(fit.correlation_size(), n * n) << fit.kind();
    for (int i = 0; i < n; ++i) {
      EXPECT_EQ(fit.correlation(i * n + i), 1.0);
      for (int j = 0; j < n; ++j) {
        // Symmetric to rounding: the covariance is symmetric up to ~1e-15 relative.
        EXPECT_NEAR(fit.correlation(i * n + j), fit.correlation(j * n + i), 1e-9);
        EXPECT_LE(std::abs(fit.correlation(i * n + j)), 1.0 + 1e-12);
      }
    }
  }
  EXPECT_EQ(Count(html, "parameter correlations"), 2u);
  // Flags exactly the parameters with |value| < 1 sigma.
  size_t small = 0;
  for (const v1::CalibrationFitResult& fit : result.fits()) {
    for (const v1::CalibrationParameter& p : fit.parameters()) {
      small += std::abs(p.value()) < p.sigma() ? 1 : 0;
    }
  }
  EXPECT_EQ(Count(html, "not distinguishable from 0"), small);
  // The table's numbers are the result's (17 significant digits round-trip a double exactly).
  for (const v1::CalibrationFitResult& fit : result.fits()) {
    for (const v1::CalibrationParameter& p : fit.parameters()) {
      const std::vector<double> cells = RowValues(html, p.name());
      ASSERT_EQ(cells.size(), 2u) << p.name();
      EXPECT_EQ(cells[0], p.value()) << p.name();
      EXPECT_EQ(cells[1], p.sigma()) << p.name();
    }
  }
  EXPECT_NE(html.find("19 static poses"), std::string::npos);  // static-detection summary
  EXPECT_NE(html.find("pose 18: t "), std::string::npos);
}

TEST(CalibrationReport, InjectedAccelBiasIsWithinFourSigmaOfTheFit) {
  // Physics check of the library path (not only of the report): the fitted accel biases against
  // the injected ones, 4 sigma (two-sided probability 6e-5 per parameter for honest sigmas;
  // tests/calib/multi_position_slow_test.cc checks the sigmas' calibration over 100 trials).
  const calib::Tumble tumble = TacticalTumble();
  const v1::CalibrationResult result = RunCalibration(ImuSettings(), ToTable(tumble.recording));
  const char* names[3] = {"accel.bias.x", "accel.bias.y", "accel.bias.z"};
  for (int i = 0; i < 3; ++i) {
    for (const v1::CalibrationParameter& p : result.fits(0).parameters()) {
      if (p.name() != names[i]) continue;
      EXPECT_LT(std::fabs(p.value() - tumble.b_a[i]), 4.0 * p.sigma()) << p.name();
    }
  }
}

TEST(CalibrationReport, CliWritesWhatRunCalibrationReturns) {
  Scratch scratch;
  const calib::Tumble tumble = TacticalTumble();
  const fs::path csv = scratch.dir() / "tumble.csv";
  {
    std::ofstream out(csv);
    out << "t_s,gx,gy,gz,ax,ay,az\n";
    char line[512];
    const calib::RawImuRecording& r = tumble.recording;
    for (size_t k = 0; k < r.size(); ++k) {
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", r.t_s[k],
                    r.omega_ib_s[k][0], r.omega_ib_s[k][1], r.omega_ib_s[k][2], r.f_ib_s[k][0],
                    r.f_ib_s[k][1], r.f_ib_s[k][2]);
      out << line;
    }
  }
  const fs::path json_path = scratch.dir() / "calib.json";
  const fs::path report_path = scratch.dir() / "calib.html";
  ASSERT_TRUE(fs::exists(DRIFTLAB_CLI)) << "build the driftlab target first: " << DRIFTLAB_CLI;
  const auto r = RunDriftlab({"calibrate", "imu", csv.string(), "--lat", "45", "--out",
                              json_path.string(), "--report", report_path.string()},
                             scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << r.out;
  v1::CalibrationResult from_cli;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(::driftlab::testing::ReadFile(json_path),
                                                          &from_cli)
                  .ok());
  CalibrateSettings settings = ImuSettings();
  settings.data_name = csv.string();
  const v1::CalibrationResult direct = RunCalibration(settings, ReadNumericCsv(csv.string()));
  // Same code path and the CSV's 17 digits round-trip every sample: identical numbers.
  ASSERT_EQ(from_cli.fits_size(), direct.fits_size());
  for (int f = 0; f < direct.fits_size(); ++f) {
    const auto& a = from_cli.fits(f);
    const auto& b = direct.fits(f);
    ASSERT_EQ(a.parameters_size(), b.parameters_size());
    for (int i = 0; i < b.parameters_size(); ++i) {
      EXPECT_EQ(a.parameters(i).name(), b.parameters(i).name());
      EXPECT_EQ(a.parameters(i).value(), b.parameters(i).value()) << b.parameters(i).name();
      EXPECT_EQ(a.parameters(i).sigma(), b.parameters(i).sigma()) << b.parameters(i).name();
    }
    EXPECT_EQ(a.residual_rms(), b.residual_rms());
    EXPECT_EQ(a.iterations(), b.iterations());
  }
  EXPECT_EQ(from_cli.data_file(), direct.data_file());
  // The CLI's report is the library's rendering of the same numbers.
  const std::string html = ::driftlab::testing::ReadFile(report_path);
  EXPECT_EQ(TagBalance(html), "");
  EXPECT_EQ(RowValues(html, "gyro.scale_factor.y").at(0), direct.fits(1).parameters(1).value());
}

TEST(CalibrationReport, ReferenceFitPlotsOneResidualPerRowAndAxis) {
  CalibrateSettings s;
  s.kind = "reference";
  s.input_unit = "deg/s";
  const NumericTable table =
      ReadNumericCsv(std::string(DRIFTLAB_CLI_TEST_DATA) + "/calib_seed003_gyro.csv");
  const v1::CalibrationResult result = RunCalibration(s, table);
  ASSERT_EQ(result.fits_size(), 3);
  // Hand derivation in tests/calib/reference_calibration_test.cc: x sensitivity 2.01/396 V/(deg/s);
  // least squares is exact to rounding (1e-12).
  EXPECT_NEAR(result.fits(0).parameters(0).value(), 2.01 / 396.0, 1e-12);
  const std::string html = RenderCalibrationReport(result);
  EXPECT_EQ(TagBalance(html), "");
  EXPECT_EQ(Count(html, "id=\"plot-residuals-reference-"), 3u);  // one plot per axis fit
  EXPECT_EQ(RowValues(html, "x.sensitivity").at(0), result.fits(0).parameters(0).value());
}

// White noise of known density on three gyro and three accel columns: N = sigma / sqrt(rate)
// (point samples). 2^16 samples at 100 Hz: N from tau 0.01-300 s with edf ~ 6e4 at the short end,
// sigma(N) < 1 %; 5 % is the required accuracy.
NumericTable WhiteNoiseTable(double n_gyro, double n_accel, double rate_hz, int samples) {
  NumericTable t;
  t.columns = {"t_s",          "omega_x_rad_per_s", "omega_y_rad_per_s", "omega_z_rad_per_s",
               "f_x_m_per_s2", "f_y_m_per_s2",      "f_z_m_per_s2"};
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, n_gyro * std::sqrt(rate_hz));
  std::normal_distribution<double> a(0.0, n_accel * std::sqrt(rate_hz));
  for (int i = 0; i < samples; ++i) {
    t.values.push_back(i / rate_hz);
    for (int k = 0; k < 3; ++k) t.values.push_back(g(rng));
    for (int k = 0; k < 3; ++k) t.values.push_back(a(rng));
  }
  return t;
}

TEST(NoiseFitReport, PlotsEveryCurveWithItsFitAndConfidenceBars) {
  const double n_gyro = 0.5 * M_PI / 180.0 / 60.0;  // 0.5 deg/sqrt(h)
  const double n_accel = 1e-3;                      // m/s/sqrt(s)
  NoiseFitSettings settings;
  settings.rate_hz = 100.0;
  settings.data_name = "white.csv";
  const v1::NoiseModelFit fit =
      RunNoiseFit(settings, WhiteNoiseTable(n_gyro, n_accel, 100.0, 1 << 16));
  ASSERT_EQ(fit.curves_size(), 6);
  int points = 0;
  for (const v1::AllanCurve& c : fit.curves()) points += c.tau_s_size();
  bool found_gyro = false, found_accel = false;
  for (const v1::NoiseTerm& t : fit.terms()) {
    if (t.axis() != "triad" || t.name() != "white_noise") continue;
    const double truth = t.triad() == "gyro" ? n_gyro : n_accel;
    EXPECT_NEAR(t.value() / truth, 1.0, 0.05) << t.triad();
    (t.triad() == "gyro" ? found_gyro : found_accel) = true;
  }
  EXPECT_TRUE(found_gyro && found_accel);
  // The written model is the triad fit (white noise in datasheet units: deg/sqrt(h)).
  EXPECT_NEAR(fit.sensor().gyro().arw_deg_per_sqrt_h() / 0.5, 1.0, 0.05);

  const std::string html = RenderNoiseFitReport(fit, "white.csv");
  EXPECT_EQ(TagBalance(html), "");
  // One interactive plot per column, in the table's units: deg/h for the gyro
  // columns, ug for the accelerometer's; measured ADEV with its interval band and the fitted
  // model; the slope guides; white noise N read off at tau = 1 s.
  EXPECT_EQ(Count(html, "id=\"plot-allan-"), 6u);
  EXPECT_EQ(Count(html, "Allan deviation [deg/h]"), 3u);
  EXPECT_EQ(Count(html, "Allan deviation [ug]"), 3u);
  EXPECT_EQ(Count(html, "\"labels\":[\"tau [s]\",\"ADEV, 95 % CI\",\"fitted model\"]"), 6u);
  EXPECT_EQ(Count(html, "\"-1/2\""), 6u);
  EXPECT_EQ(Count(html, "\"+1/2\""), 6u);
  EXPECT_GE(Count(html, "\"N = "), 6u);
  EXPECT_GT(points, 6 * 3);
  EXPECT_NE(html.find("&quot;arw_deg_per_sqrt_h&quot;"), std::string::npos);  // sensor JSON
  EXPECT_NE(html.find("not determined"), std::string::npos);  // no B, K, Q, R in white noise
  // Every term's value and sigma in the table are the fit's (rows: triad, axis, term).
  for (const v1::NoiseTerm& t : fit.terms()) {
    const std::string key =
        "<tr><td>" + t.triad() + "</td><td>" + t.axis() + "</td><td>" + t.name() + "</td>";
    const size_t at = html.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    const size_t v = html.find("data-value=\"", at);
    EXPECT_EQ(std::stod(html.substr(v + 12)), t.value()) << key;
  }
}

TEST(NoiseFitCore, DatasheetFiguresStandBesideTheTriadTerms) {
  NoiseFitSettings settings;
  settings.rate_hz = 100.0;
  std::ifstream in(std::string(DRIFTLAB_CLI_TEST_DATA) + "/datasheet_tactical.yaml");
  settings.datasheet_yaml.assign(std::istreambuf_iterator<char>(in), {});
  const v1::NoiseModelFit fit = RunNoiseFit(settings, WhiteNoiseTable(1e-4, 1e-3, 100.0, 1 << 14));
  bool compared = false;
  for (const v1::NoiseTerm& t : fit.terms()) {
    if (t.triad() == "gyro" && t.axis() == "triad" && t.name() == "white_noise") {
      ASSERT_TRUE(t.has_datasheet_value());
      // datasheet_tactical.yaml: arw 0.15 deg/sqrt(h) = 0.15 pi / 180 / 60 rad/sqrt(s) (exact
      // conversion through the units module, 1e-12 relative for rounding).
      EXPECT_NEAR(t.datasheet_value(), 0.15 * M_PI / 180.0 / 60.0, 1e-12 * t.datasheet_value());
      compared = true;
    }
    if (t.axis() != "triad") {
      EXPECT_FALSE(t.has_datasheet_value());
    }
  }
  EXPECT_TRUE(compared);
  EXPECT_NE(RenderNoiseFitReport(fit, "x").find("<th>datasheet</th>"), std::string::npos);
}

using testing::ErrorOf;

TEST(CalibrationCore, BadSettingsAndTablesNameTheFieldAndTheValue) {
  const NumericTable table = ToTable(TacticalTumble().recording);
  CalibrateSettings s = ImuSettings();
  s.kind = "magnetometer";
  EXPECT_NE(ErrorOf([&] { RunCalibration(s, table); }).find("kind: 'magnetometer'"),
            std::string::npos);
  s = ImuSettings();
  s.lat_deg = 91;
  EXPECT_NE(ErrorOf([&] { RunCalibration(s, table); }).find("lat_deg: 91"), std::string::npos);
  s = ImuSettings();
  s.rate_hz = 100;  // then the header must name gx, gy, gz, ax, ay, az without t_s
  EXPECT_NE(ErrorOf([&] { RunCalibration(s, table); }).find("data: header: t_s, gx"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { RunCalibration(s, table); }).find("(unknown t_s)"), std::string::npos);
  NumericTable bad = table;
  bad.values[7 * 100 + 4] = NAN;
  EXPECT_NE(ErrorOf([&] { RunCalibration(ImuSettings(), bad); }).find("row 101 column 'ax'"),
            std::string::npos);
  NumericTable still = table;
  for (size_t k = 0; k < still.rows(); ++k) {  // every sample as the first: one pose only
    for (int c = 1; c < 7; ++c) still.values[7 * k + c] = table.values[c];
  }
  EXPECT_NE(ErrorOf([&] { RunCalibration(ImuSettings(), still); }).find("too few poses"),
            std::string::npos);
  NoiseFitSettings n;
  n.rate_hz = 100;
  n.columns = {"gx"};
  EXPECT_NE(ErrorOf([&] { RunNoiseFit(n, table); }).find("columns: missing"), std::string::npos);
  n.columns = {"nope"};
  EXPECT_NE(ErrorOf([&] { RunNoiseFit(n, table); }).find("columns: 'nope'"), std::string::npos);
}

TEST(CalibrationCore, ReadNumericCsvNamesFileLineAndColumn) {
  Scratch scratch;
  const std::string path = (scratch.dir() / "d.csv").string();
  std::ofstream(path) << "# comment\n1,2,3\n\n4,5,6\n";
  const NumericTable headerless = ReadNumericCsv(path);
  EXPECT_EQ(headerless.columns, (std::vector<std::string>{"column1", "column2", "column3"}));
  EXPECT_EQ(headerless.values, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  std::ofstream(path) << "a,b\n1,2\n3\n";
  EXPECT_NE(ErrorOf([&] { ReadNumericCsv(path); }).find("d.csv:3: 1 columns; expected 2"),
            std::string::npos);
  std::ofstream(path) << "a,b\n1,2\n3,inf\n";
  EXPECT_NE(ErrorOf([&] { ReadNumericCsv(path); }).find("d.csv:3: column 'b': 'inf'"),
            std::string::npos);
  // Selected columns: a missing one is reported before the bad row is read.
  EXPECT_NE(ErrorOf([&] {
              ReadNumericCsv(path, {"a", "c"}, "--columns");
            }).find("--columns: 'c'"),
            std::string::npos);
  std::ofstream(path) << "a,b,c\n1,2,3\n4,5,6\n";
  const NumericTable selected = ReadNumericCsv(path, {"c", "a"}, "--columns");
  EXPECT_EQ(selected.values, (std::vector<double>{3, 1, 6, 4}));
}

}  // namespace
}  // namespace driftlab::app
