#include "report_scenario.h"

#include <fmt/format.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "driftlab/app/sensor_model.h"
#include "driftlab/app/translate.h"
#include "driftlab/earth.h"
#include "driftlab/report/html_report.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/trajectory.h"
#include "driftlab/units.h"
#include "report_style.h"
#include "svg_plot.h"

namespace driftlab::app {

namespace {

using svg::Num;

std::string Fact(const std::string& name, const std::string& value) {
  return "<tr><th>" + EscapeHtml(name) + "</th><td>" + EscapeHtml(value) + "</td></tr>\n";
}

// The IMU figures of triad t in the report units of the sensor-term table (sensor_terms.h): the
// scalar terms in the table's order (a correlation time only with its sigma), then the norms of
// the vector terms; terms that are off are left out.
std::string TriadFigures(const ImuErrorModel& model, SensorTriad t) {
  std::vector<std::string> parts;
  const auto add = [&](std::string_view name, double si, std::string_view unit) {
    if (si != 0) parts.push_back(fmt::format("{} {}", name, FormatQuantity(si, unit, 3)));
  };
  for (const bool vectors : {false, true}) {
    for (const SensorTerm& term : SensorTerms()) {
      const std::string_view label = term.report_label.of(t);
      if (label.empty() || !term.applies_to(t)) continue;
      if (term.written_with != 0 &&
          TermValue(*SensorTermByField(term.written_with), model, t, 0) == 0) {
        continue;
      }
      const int count = TermValueCount(term.shape);
      if ((count > 1) != vectors) continue;
      double sum_of_squares = 0;
      for (int i = 0; i < count; ++i) {
        const double v = TermValue(term, model, t, i);
        sum_of_squares += v * v;
      }
      add(label, count == 1 ? TermValue(term, model, t, 0) : std::sqrt(sum_of_squares),
          term.report_unit.of(t));
    }
  }
  return parts.empty() ? "ideal" : fmt::format("{}", fmt::join(parts, ", "));
}

// One aid of the job, named by its field, with the values the job sets for it (the defaults of the
// rest: docs/aiding.md), read by reflection so that a new aid needs no line here.
std::string AidText(const google::protobuf::Message& aid, const std::string& name) {
  using google::protobuf::FieldDescriptor;
  const google::protobuf::Reflection* r = aid.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  r->ListFields(aid, &fields);
  std::vector<std::string> values;
  for (const FieldDescriptor* f : fields) {
    std::string v;
    if (f->is_repeated()) {
      if (f->cpp_type() != FieldDescriptor::CPPTYPE_DOUBLE) {
        v = fmt::format("{} entries", r->FieldSize(aid, f));
      } else {
        std::vector<std::string> items;
        for (int i = 0; i < r->FieldSize(aid, f); ++i) {
          items.push_back(Num(r->GetRepeatedDouble(aid, f, i)));
        }
        v = fmt::format("[{}]", fmt::join(items, ", "));
      }
    } else {
      switch (f->cpp_type()) {
        case FieldDescriptor::CPPTYPE_DOUBLE:
          v = Num(r->GetDouble(aid, f));
          break;
        case FieldDescriptor::CPPTYPE_BOOL:
          v = r->GetBool(aid, f) ? "true" : "false";
          break;
        case FieldDescriptor::CPPTYPE_ENUM:
          v = r->GetEnum(aid, f)->name();
          break;
        case FieldDescriptor::CPPTYPE_INT32:
        case FieldDescriptor::CPPTYPE_UINT32:
        case FieldDescriptor::CPPTYPE_INT64:
        case FieldDescriptor::CPPTYPE_UINT64: {
          std::string text;
          google::protobuf::TextFormat::PrintFieldValueToString(aid, f, -1, &text);
          v = text;
          break;
        }
        default:
          continue;  // nested messages: named by the aid's page, not repeated here
      }
    }
    values.push_back(fmt::format("{} {}", f->name(), v));
  }
  return values.empty() ? name : fmt::format("{} ({})", name, fmt::join(values, ", "));
}

std::string AidingText(const v1::Job& job) {
  std::vector<std::string> parts;
  const v1::Aiding& a = job.aiding();
  if (a.has_gnss()) {
    parts.push_back(fmt::format(
        "GNSS at {} Hz{}", Num(a.gnss().has_rate_hz() ? a.gnss().rate_hz() : 1.0),
        a.gnss().outages().empty() ? "" : fmt::format(", {} outage(s)", a.gnss().outages_size())));
  }
  if (a.zupt().enabled()) parts.push_back("ZUPT while static");
  // The other aids: every set field of the job's aiding section in the schema's order.
  const google::protobuf::Reflection* r = a.GetReflection();
  std::vector<const google::protobuf::FieldDescriptor*> fields;
  r->ListFields(a, &fields);
  for (const google::protobuf::FieldDescriptor* f : fields) {
    if (f->name() == "gnss" || f->name() == "zupt" ||
        f->cpp_type() != google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE) {
      continue;
    }
    parts.push_back(AidText(r->GetMessage(a, f), f->name()));
  }
  return parts.empty() ? "none (free inertial)" : fmt::format("{}", fmt::join(parts, ", "));
}

}  // namespace

Scenario RegenerateScenario(const v1::JobResult& result) {
  Scenario s;
  const v1::Job& job = result.job();
  for (const v1::GnssOutage& o : job.aiding().gnss().outages()) {
    s.outages_s.emplace_back(o.start_s(), o.end_s());
  }
  try {
    const SimulationSpec spec = ToSimulationSpec(job, ".");
    TrajectoryGenerator generator(spec.motion, spec.rate_hz);
    s.duration_s = generator.duration_s();
    if (job.aiding().has_gnss()) {
      for (const auto& w : generator.gps_invisible_s()) s.outages_s.push_back(w);
    }
    if (generator.num_steps() > kMaxTrajectorySteps) {
      s.note = fmt::format("the trajectory has {} steps (the report regenerates at most {})",
                           generator.num_steps(), kMaxTrajectorySteps);
      return s;
    }
    const int64_t stride = std::max<int64_t>(1, generator.num_steps() / kMaxDrawnEpochs);
    const Llh start = generator.initial_state().llh;
    // North/east of the start on the local tangent plane: dN = R_N dL, dE = R_E cos L dlambda
    // (Groves (2.119), curvature at the start; flat-Earth jobs use the same radii).
    const double r_n = MeridianRadius(start.lat_rad) + start.h_m;
    const double r_e = (TransverseRadius(start.lat_rad) + start.h_m) * std::cos(start.lat_rad);
    const auto add = [&](const NavState& truth) {
      s.north_m.push_back((truth.llh.lat_rad - start.lat_rad) * r_n);
      s.east_m.push_back((truth.llh.lon_rad - start.lon_rad) * r_e);
    };
    add(generator.initial_state());
    const bool zupt = job.aiding().zupt().enabled();
    double zupt_start = generator.IsStaticAt(0) ? 0.0 : -1.0;
    TrajectorySample sample;
    while (generator.Next(&sample)) {
      const double speed = sample.truth.v_eb_n.norm();
      s.distance_m += speed * generator.dt_s();
      s.max_speed_m_per_s = std::max(s.max_speed_m_per_s, speed);
      if (generator.step() % stride == 0 || generator.step() == generator.num_steps()) {
        add(sample.truth);
      }
      if (zupt) {
        const bool still = generator.IsStaticAt(sample.truth.t_s);
        if (still && zupt_start < 0) zupt_start = sample.truth.t_s;
        if (!still && zupt_start >= 0) {
          s.zupts_s.emplace_back(zupt_start, sample.truth.t_s);
          zupt_start = -1;
        }
      }
    }
    if (zupt && zupt_start >= 0) s.zupts_s.emplace_back(zupt_start, s.duration_s);
    s.regenerated = true;
  } catch (const std::exception& e) {
    s.note = std::string("the motion could not be regenerated here: ") + e.what();
  }
  return s;
}

std::string SetupTable(const v1::JobResult& result, const Scenario& scenario) {
  const v1::Job& job = result.job();
  std::string rows;
  const double final_t = result.epochs().rbegin()->t_s();
  std::string motion = fmt::format("{} s", Num(final_t));
  if (job.motion().segments_size() > 0) {
    motion += fmt::format(", {} segment(s)", job.motion().segments_size());
  }
  if (scenario.regenerated) {
    motion += fmt::format(", {:.0f} m travelled, top speed {:.1f} m/s", scenario.distance_m,
                          scenario.max_speed_m_per_s);
  }
  rows += Fact("motion", motion);
  const double rate = job.has_rate_hz() ? job.rate_hz() : 100.0;
  rows += Fact("IMU rate", fmt::format("{} Hz", Num(rate)));
  try {
    const std::optional<ImuErrorModel> model = ToImuErrorModel(job);
    if (!model) {
      rows += Fact("IMU model", "ideal (no sensor errors)");
    } else {
      rows += Fact("IMU model", model->name.empty() ? "(custom)" : model->name);
      rows += Fact("gyro", TriadFigures(*model, SensorTriad::kGyro));
      rows += Fact("accelerometer", TriadFigures(*model, SensorTriad::kAccel));
    }
  } catch (const std::exception& e) {
    rows += Fact("IMU model", e.what());
  }
  rows += Fact("mechanization",
               v1::Navigation::Mechanization_Name(job.navigation().mechanization() ==
                                                          v1::Navigation::MECHANIZATION_UNSPECIFIED
                                                      ? v1::Navigation::NED
                                                      : job.navigation().mechanization()));
  rows += Fact("aiding", AidingText(job));
  rows += Fact("filter", job.navigation().filter() == v1::Navigation::FILTER_UNSPECIFIED
                             ? "NONE (free inertial)"
                             : v1::Navigation::Filter_Name(job.navigation().filter()));
  rows += Fact("runs", fmt::format("{} (seed {})", result.runs(), result.seed()));
  return "<table class=\"facts\"><caption>What was simulated</caption>\n" + rows + "</table>\n";
}

std::vector<plot::Shade> Shades(const Scenario& scenario) {
  std::vector<plot::Shade> shades;
  const std::string outage = kOutageShade, zupt = kZuptShade;
  for (const auto& [a, b] : scenario.outages_s) shades.push_back(plot::Shade{a, b, outage});
  for (const auto& [a, b] : scenario.zupts_s) shades.push_back(plot::Shade{a, b, zupt});
  return shades;
}

std::string ShadeKey(const Scenario& scenario) {
  std::string key;
  if (!scenario.outages_s.empty()) {
    key += fmt::format("<span class=\"key\" style=\"background:{}\"></span>GNSS outage ",
                       kOutageShade);
  }
  if (!scenario.zupts_s.empty()) {
    key += fmt::format("<span class=\"key\" style=\"background:{}\"></span>ZUPT (static) ",
                       kZuptShade);
  }
  return key;
}

std::string TrajectoryPlot(const Scenario& scenario) {
  if (!scenario.regenerated)
    return "<p>No trajectory plot: " + EscapeHtml(scenario.note) + ".</p>\n";
  // dygraphs needs ascending x: the track is drawn as north against east only when east is
  // monotonic; in general each point is one row (x = east) of a points-only series, so a track
  // that turns back is still drawn as its points.
  std::vector<size_t> order(scenario.east_m.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return scenario.east_m[a] < scenario.east_m[b]; });
  plot::Plot p;
  p.name = "trajectory";
  p.x_label = "east of start [m]";
  p.y_label = "north of start [m]";
  p.points_only = true;
  p.equal_axes = true;
  p.width_px = 440;
  p.height_px = 360;
  plot::Series track{"truth", kMeanColor, {}, {}, {}, {}, 1.5};
  for (const size_t i : order) {
    p.x.push_back(scenario.east_m[i]);
    track.y.push_back(scenario.north_m[i]);
  }
  p.series.push_back(track);
  // Axes fit the track with a 5 % margin (equal scales widen the shorter one).
  const auto [east_lo, east_hi] =
      std::minmax_element(scenario.east_m.begin(), scenario.east_m.end());
  const auto [north_lo, north_hi] =
      std::minmax_element(scenario.north_m.begin(), scenario.north_m.end());
  const double pad = 0.05 * std::max({*east_hi - *east_lo, *north_hi - *north_lo, 1.0});
  p.x_range = {*east_lo - pad, *east_hi + pad};
  p.y_range = {*north_lo - pad, *north_hi + pad};
  p.markers.push_back({scenario.east_m.front(), scenario.north_m.front(), kCep50Color, "start"});
  p.markers.push_back({scenario.east_m.back(), scenario.north_m.back(), kRmsColor, "end"});
  return plot::Figure(p, fmt::format("true trajectory, north against east of the start (equal "
                                     "scales), {} s",
                                     Num(scenario.duration_s)));
}

}  // namespace driftlab::app
