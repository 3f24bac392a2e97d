#include "driftlab/app/error_budget_job.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "driftlab/app/consistency_check.h"
#include "driftlab/app/job_result.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::app {
namespace {

namespace util = google::protobuf::util;

constexpr int kCheckedComponents = 9;  // position, velocity, attitude (ErrorComponent 1-9)

bool IsAngle(int c) { return c >= 6 && c <= 8; }

// Variance of component c in the result's unit squared.
double ToResultVariance(int c, double variance_si) {
  return IsAngle(c) ? variance_si * kRadToDeg * kRadToDeg : variance_si;
}

const char* FilterText(NavigationFilterKind f) {
  return f == NavigationFilterKind::kInsGnssEkf ? "INS_GNSS_EKF" : "NONE";
}

bool IsImuSource(const ErrorSource& s) { return s.group == "gyro" || s.group == "accel"; }

// The sensor term and triad a source "<triad>.<datasheet key>" names, or nullptr.
const SensorTerm* TermOfSource(const std::string& name, SensorTriad* triad) {
  const size_t dot = name.find('.');
  if (dot == std::string::npos) return nullptr;
  const std::string prefix = name.substr(0, dot), key = name.substr(dot + 1);
  if (prefix != "gyro" && prefix != "accel") return nullptr;
  *triad = prefix == "gyro" ? SensorTriad::kGyro : SensorTriad::kAccel;
  for (const SensorTerm& term : SensorTerms()) {
    if (term.datasheet_key.of(*triad) == key && term.applies_to(*triad)) return &term;
  }
  return nullptr;
}

// Every error term of `model` zeroed except `keep` of triad `keep_triad` (nullptr: all zeroed).
// Correlation times and options (terms written with another) stay: they do nothing alone.
ImuErrorModel OnlyTerm(const ImuErrorModel& model, const SensorTerm* keep, SensorTriad keep_triad) {
  ImuErrorModel out = model;
  for (const SensorTerm& term : SensorTerms()) {
    if (term.shape == TermShape::kFlag || term.written_with != 0) continue;
    for (const SensorTriad t : {SensorTriad::kGyro, SensorTriad::kAccel}) {
      if (!term.applies_to(t) || (&term == keep && t == keep_triad)) continue;
      for (int i = 0; i < TermValueCount(term.shape); ++i) SetTermValue(term, &out, t, i, 0.0);
    }
  }
  return out;
}

}  // namespace

v1::ErrorBudget ToErrorBudget(const v1::Job& job, const ErrorBudgetResult& budget,
                              const std::string& engine_version) {
  v1::ErrorBudget out;
  *out.mutable_job() = job;
  out.set_engine_version(engine_version);
  out.set_filter(FilterText(budget.filter));
  out.set_step_samples(static_cast<uint32_t>(budget.step_samples));
  for (const double t : budget.epoch_times_s) out.add_t_s(t);
  for (int c = 0; c < kNumErrorComponents; ++c) {
    out.add_components(static_cast<v1::ErrorComponent>(c + 1));
    v1::VarianceSeries* total = out.add_total();
    total->set_component(static_cast<v1::ErrorComponent>(c + 1));
    for (const ComponentVariances& v : budget.total) {
      total->add_variance(ToResultVariance(c, v[static_cast<size_t>(c)]));
    }
  }
  // Rank: the final contribution to the first component (horizontal, 3-D, yaw) with a nonzero
  // total.
  std::vector<size_t> order(budget.sources.size());
  std::iota(order.begin(), order.end(), size_t{0});
  if (!budget.total.empty()) {
    const size_t last = budget.total.size() - 1;
    int rank_c = static_cast<int>(ErrorComponent::kYaw);
    for (const ErrorComponent c :
         {ErrorComponent::kHorizontalPosition, ErrorComponent::kPosition3d}) {
      if (budget.total[last][static_cast<size_t>(c)] > 0.0) {
        rank_c = static_cast<int>(c);
        break;
      }
    }
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return budget.contribution[last][a][static_cast<size_t>(rank_c)] >
             budget.contribution[last][b][static_cast<size_t>(rank_c)];
    });
  }
  for (const size_t s : order) {
    // A source with no contribution at any epoch (an aid's rows the job does not measure) is
    // left out.
    bool any = false;
    for (const auto& epoch : budget.contribution) {
      for (const double v : epoch[s]) any = any || v != 0.0;
    }
    if (!any) continue;
    v1::BudgetSource* src = out.add_sources();
    src->set_name(budget.sources[s].name);
    src->set_group(budget.sources[s].group);
    for (int c = 0; c < kNumErrorComponents; ++c) {
      v1::VarianceSeries* series = src->add_series();
      series->set_component(static_cast<v1::ErrorComponent>(c + 1));
      for (const auto& epoch : budget.contribution) {
        series->add_variance(ToResultVariance(c, epoch[s][static_cast<size_t>(c)]));
      }
    }
  }
  out.set_max_relative_sum_error(budget.max_relative_sum_error);
  for (const std::string& u : budget.unrepresented) out.add_unrepresented(u);
  out.set_verdict(BudgetVerdict(out));
  return out;
}

std::string ErrorBudgetToJson(const v1::ErrorBudget& budget) {
  util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const util::Status status = util::MessageToJsonString(budget, &json, options);
  if (!status.ok()) throw SpecError("budget", std::string(status.message()), "a printable budget");
  return json;
}

MonteCarloSpec BudgetCheckSpec(const MonteCarloSpec& spec, const ErrorBudgetResult& budget,
                               const std::string& source, uint32_t runs,
                               std::vector<std::string>* switched_on) {
  const auto it = std::find_if(budget.sources.begin(), budget.sources.end(),
                               [&](const ErrorSource& s) { return s.name == source; });
  if (it == budget.sources.end()) {
    throw SpecError("--mc-check", source, "a source of the budget");
  }
  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  MonteCarloSpec out = spec;
  out.covariance = false;
  out.runs = runs;
  out.first_run = 0;
  out.run_count = 0;
  switched_on->clear();
  if (ekf) out.filter_sensor = spec.sensor;  // the filter keeps its model: its gains stay
  if (IsImuSource(*it)) {
    SensorTriad triad = SensorTriad::kGyro;
    const SensorTerm* term = TermOfSource(it->name, &triad);
    if (term == nullptr) {
      throw SpecError("--mc-check", source,
                      "a source the Monte Carlo can switch on alone (a sensor term)");
    }
    out.sensor = OnlyTerm(spec.sensor.value_or(ImuErrorModel{}), term, triad);
    switched_on->push_back(it->name);
    if (!ekf) out.initial_errors = InitialErrorSigmas{};
  } else {
    if (spec.sensor) out.sensor = OnlyTerm(*spec.sensor, nullptr, SensorTriad::kGyro);
    if (!ekf) {
      // Free inertial: only this initial error.
      InitialErrorSigmas only;
      if (it->name == "initial.position") only.position_ned_m = spec.initial_errors.position_ned_m;
      if (it->name == "initial.velocity") {
        only.velocity_ned_m_per_s = spec.initial_errors.velocity_ned_m_per_s;
      }
      if (it->name == "initial.attitude") only.attitude_rad = spec.initial_errors.attitude_rad;
      out.initial_errors = only;
      switched_on->push_back(it->name);
    }
  }
  if (ekf) {
    // The filter's initial errors and its aids' errors stay in the truth.
    for (const ErrorSource& s : budget.sources) {
      if (!IsImuSource(s) && s.name != it->name) switched_on->push_back(s.name);
    }
    if (!IsImuSource(*it)) switched_on->insert(switched_on->begin(), it->name);
  }
  return out;
}

void CheckErrorBudget(const MonteCarloSpec& spec, const ErrorBudgetResult& budget, uint32_t runs,
                      int top, double alpha, v1::ErrorBudget* out,
                      const std::function<void(const std::string&)>& progress) {
  out->clear_checks();
  out->set_check_alpha(alpha);
  if (budget.contribution.empty() || runs < 2) {
    out->set_verdict(BudgetVerdict(*out));
    return;
  }
  const size_t last = budget.contribution.size() - 1;
  struct Pending {
    std::string source;
    std::vector<std::string> on;
    std::array<double, kCheckedComponents> predicted_sigma{};  // result units
    v1::JobResult result;
  };
  std::vector<Pending> checks;
  std::vector<std::vector<std::string>> sets_run;  // sorted switched-on sets already checked
  for (int i = 0; static_cast<int>(checks.size()) < top && i < out->sources_size(); ++i) {
    const std::string& name = out->sources(i).name();
    Pending p;
    p.source = name;
    const MonteCarloSpec check = BudgetCheckSpec(spec, budget, name, runs, &p.on);
    // A filter's aid and initial-error sources share one check (they stay on together): the
    // next source with a set not yet run takes the place of a repeat.
    std::vector<std::string> set = p.on;
    std::sort(set.begin(), set.end());
    if (std::find(sets_run.begin(), sets_run.end(), set) != sets_run.end()) continue;
    sets_run.push_back(std::move(set));
    for (int c = 0; c < kCheckedComponents; ++c) {
      double variance = 0.0;
      for (size_t s = 0; s < budget.sources.size(); ++s) {
        if (std::find(p.on.begin(), p.on.end(), budget.sources[s].name) != p.on.end()) {
          variance += budget.contribution[last][s][static_cast<size_t>(c)];
        }
      }
      p.predicted_sigma[static_cast<size_t>(c)] = std::sqrt(ToResultVariance(c, variance));
    }
    if (progress) progress(name);
    const MonteCarloOutput output = RunMonteCarloWithAnalysis(check);
    p.result = ToJobResult(v1::Job(), output, "", 0.0);
    checks.push_back(std::move(p));
  }
  // Bonferroni over every component tested in every check.
  int tested = 0;
  for (const Pending& p : checks) {
    for (int c = 0; c < kCheckedComponents; ++c) {
      tested += p.predicted_sigma[static_cast<size_t>(c)] > 0.0 ? 1 : 0;
    }
  }
  for (const Pending& p : checks) {
    v1::BudgetCheck* check = out->add_checks();
    check->set_source(p.source);
    for (const std::string& s : p.on) check->add_switched_on(s);
    check->set_runs(runs);
    check->set_seed(spec.seed);
    const v1::EpochStatistics& final_epoch = *p.result.epochs().rbegin();
    check->set_t_s(final_epoch.t_s());
    bool pass = true;
    for (int c = 0; c < kCheckedComponents; ++c) {
      const double sigma_p = p.predicted_sigma[static_cast<size_t>(c)];
      if (!(sigma_p > 0.0)) continue;
      const double s = final_epoch.components(c).std();
      const RatioInterval r =
          SigmaRatioInterval(s, sigma_p, runs, alpha / static_cast<double>(tested));
      v1::BudgetCheckComponent* cc = check->add_components();
      cc->set_component(static_cast<v1::ErrorComponent>(c + 1));
      cc->set_predicted_sigma(sigma_p);
      cc->set_mc_std(s);
      cc->set_ratio(r.ratio);
      cc->set_ratio_low(r.low);
      cc->set_ratio_high(r.high);
      cc->set_inside(r.low <= 1.0 && r.high >= 1.0);
      pass = pass && cc->inside();
    }
    check->set_pass(pass);
  }
  out->set_verdict(BudgetVerdict(*out));
}

std::string BudgetVerdict(const v1::ErrorBudget& budget) {
  if (budget.checks_size() == 0) return "not checked by Monte Carlo (--mc-check RUNS)";
  std::vector<std::string> failed;
  for (const v1::BudgetCheck& check : budget.checks()) {
    for (const v1::BudgetCheckComponent& c : check.components()) {
      if (!c.inside()) {
        failed.push_back(fmt::format("{}: {} {:.3g} [{:.3g}, {:.3g}]", check.source(),
                                     ConsistencyComponentName(static_cast<int>(c.component()) - 1),
                                     c.ratio(), c.ratio_low(), c.ratio_high()));
      }
    }
  }
  const v1::BudgetCheck& first = budget.checks(0);
  if (failed.empty()) {
    return fmt::format(
        "confirmed at family-wise level {:g}: Monte-Carlo/predicted sigma consistent with 1 for "
        "every component of the {} sources checked ({} runs each, t = {:g} s)",
        budget.check_alpha(), budget.checks_size(), first.runs(), first.t_s());
  }
  return fmt::format("NOT CONFIRMED at family-wise level {:g}: Monte-Carlo/predicted sigma {}",
                     budget.check_alpha(), fmt::join(failed, ", "));
}

}  // namespace driftlab::app
