#include "driftlab/report/budget_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "driftlab/app/consistency_check.h"
#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "interactive_plot.h"
#include "report_style.h"
#include "svg_plot.h"

namespace driftlab::app {
namespace {

// Stacked plots: the first kStackedSources sources by rank each, the rest summed as "other".
constexpr int kStackedSources = 8;
constexpr int kTableSources = 5;      // top sources per checkpoint in the tables
constexpr int kTableCheckpoints = 6;  // checkpoints: evenly spaced epochs, the last included

constexpr const char* kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"};

// A component group of the report: the variance of the group is the sum over its components.
struct Group {
  const char* name;
  const char* unit;  // of the variance
  std::vector<v1::ErrorComponent> components;
};

const std::vector<Group>& Groups() {
  static const std::vector<Group> kGroups = {
      {"horizontal position", "m^2", {v1::POSITION_NORTH_M, v1::POSITION_EAST_M}},
      {"vertical position", "m^2", {v1::POSITION_DOWN_M}},
      {"attitude (roll + pitch + yaw)", "deg^2", {v1::ROLL_DEG, v1::PITCH_DEG, v1::YAW_DEG}},
  };
  return kGroups;
}

// Index of `c` in the budget's component list, or -1.
int ComponentIndex(const v1::ErrorBudget& b, v1::ErrorComponent c) {
  for (int i = 0; i < b.components_size(); ++i) {
    if (b.components(i) == c) return i;
  }
  return -1;
}

// The group's variance at every epoch from a list of series (a source's or the total).
std::vector<double> GroupVariance(const v1::ErrorBudget& b, const Group& g,
                                  const google::protobuf::RepeatedPtrField<v1::VarianceSeries>& s) {
  std::vector<double> v(static_cast<size_t>(b.t_s_size()), 0.0);
  for (const v1::ErrorComponent c : g.components) {
    const int i = ComponentIndex(b, c);
    if (i < 0 || i >= s.size()) continue;
    for (int e = 0; e < s[i].variance_size() && e < b.t_s_size(); ++e) {
      v[static_cast<size_t>(e)] += s[i].variance(e);
    }
  }
  return v;
}

std::string StackedFigure(const v1::ErrorBudget& b, const Group& g) {
  plot::Plot p;
  p.name = std::string("budget-") + g.name;
  p.x_label = "t [s]";
  p.y_label = fmt::format("variance [{}]", g.unit);
  p.x.assign(b.t_s().begin(), b.t_s().end());
  p.fill = true;
  std::vector<double> cumulative(p.x.size(), 0.0);
  const int n = b.sources_size();
  for (int s = 0; s < n && s <= kStackedSources; ++s) {
    std::vector<double> add(p.x.size(), 0.0);
    std::string label;
    if (s < kStackedSources) {
      add = GroupVariance(b, g, b.sources(s).series());
      label = b.sources(s).name();
    } else {
      for (int r = kStackedSources; r < n; ++r) {
        const std::vector<double> v = GroupVariance(b, g, b.sources(r).series());
        for (size_t e = 0; e < add.size(); ++e) add[e] += v[e];
      }
      label = fmt::format("other {} sources", n - kStackedSources);
    }
    for (size_t e = 0; e < add.size(); ++e) cumulative[e] += add[e];
    plot::Series series;
    series.label = "+ " + label;
    series.color = kPalette[s % (sizeof(kPalette) / sizeof(kPalette[0]))];
    series.y = cumulative;
    p.series.push_back(std::move(series));
  }
  plot::Series total;
  total.label = "total (covariance analysis)";
  total.color = kPredictedColor;
  total.y = GroupVariance(b, g, b.total());
  total.dash = {4, 3};
  p.series.push_back(std::move(total));
  return plot::Figure(p, fmt::format("{}: each source's variance stacked on the ones above it in "
                                     "the legend (largest final contribution first); the dashed "
                                     "line is the total of the full covariance analysis.",
                                     g.name));
}

std::string CheckpointTable(const v1::ErrorBudget& b, const Group& g) {
  const int n_epochs = b.t_s_size();
  if (n_epochs == 0) return "";
  std::vector<int> epochs;
  for (int k = 1; k <= kTableCheckpoints; ++k) {
    const int e =
        static_cast<int>(std::lround(static_cast<double>(k) * (n_epochs - 1) / kTableCheckpoints));
    if (epochs.empty() || epochs.back() != e) epochs.push_back(e);
  }
  const std::vector<double> total = GroupVariance(b, g, b.total());
  std::vector<std::vector<double>> per_source;
  for (const v1::BudgetSource& s : b.sources())
    per_source.push_back(GroupVariance(b, g, s.series()));
  std::string html = fmt::format(
      "<table><caption>{}: top sources (share of the variance)</caption>"
      "<tr><th>t [s]</th><th>total RMS</th>",
      EscapeHtml(g.name));
  for (int r = 1; r <= kTableSources; ++r) html += fmt::format("<th>#{}</th>", r);
  html += "</tr>\n";
  for (const int e : epochs) {
    const size_t ue = static_cast<size_t>(e);
    std::vector<int> order(per_source.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(), [&](int a, int c) {
      return per_source[static_cast<size_t>(a)][ue] > per_source[static_cast<size_t>(c)][ue];
    });
    html += fmt::format("<tr><td>{}</td><td>{} {}</td>", svg::Num(b.t_s(e)),
                        svg::Num(std::sqrt(std::max(0.0, total[ue]))),
                        g.unit == std::string("m^2") ? "m" : "deg");
    for (int r = 0; r < kTableSources; ++r) {
      if (r >= static_cast<int>(order.size()) || !(total[ue] > 0.0)) {
        html += "<td></td>";
        continue;
      }
      const int s = order[static_cast<size_t>(r)];
      html += fmt::format("<td>{} {:.1f} %</td>", EscapeHtml(b.sources(s).name()),
                          100.0 * per_source[static_cast<size_t>(s)][ue] / total[ue]);
    }
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

std::string CheckTable(const v1::ErrorBudget& b) {
  if (b.checks_size() == 0) return "<p>No Monte-Carlo check (<code>--mc-check RUNS</code>).</p>\n";
  std::string html =
      "<table><caption>Monte-Carlo check: sample sigma / predicted sigma of the switched-on "
      "sources, with its interval</caption><tr><th>source</th><th>component</th><th>predicted "
      "sigma</th><th>MC std</th><th>ratio</th><th>interval</th><th>inside</th></tr>\n";
  for (const v1::BudgetCheck& check : b.checks()) {
    for (const v1::BudgetCheckComponent& c : check.components()) {
      html += fmt::format(
          "<tr><td>{}</td><td>{} [{}]</td><td>{}</td><td>{}</td><td>{}</td><td>[{}, "
          "{}]</td><td>{}</td></tr>\n",
          EscapeHtml(check.source()), EscapeHtml(ComponentKey(c.component())),
          EscapeHtml(ComponentUnit(c.component())), svg::Num(c.predicted_sigma()),
          svg::Num(c.mc_std()), svg::Num(c.ratio()), svg::Num(c.ratio_low()),
          svg::Num(c.ratio_high()), c.inside() ? "yes" : "NO");
    }
  }
  html += "</table>\n<p>Sources switched on in each check: ";
  for (const v1::BudgetCheck& check : b.checks()) {
    std::vector<std::string> on(check.switched_on().begin(), check.switched_on().end());
    html +=
        fmt::format("<br/>{}: {} ({} runs, seed {})", EscapeHtml(check.source()),
                    EscapeHtml(fmt::format("{}", fmt::join(on, ", "))), check.runs(), check.seed());
  }
  return html + "</p>\n";
}

}  // namespace

std::string RenderBudgetReport(const v1::ErrorBudget& b) {
  const std::string title =
      "driftlab error budget: " +
      (b.job().name().empty() ? std::string("(unnamed job)") : b.job().name());
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>" +
      EscapeHtml(title) + "</title>\n" + svg::kStyle + plot::PlotLibrary() +
      "</head>\n<body>\n<h1>" + EscapeHtml(title) + "</h1>\n";
  html += fmt::format(
      "<p>Filter {}, propagation every {} IMU samples; {} sources. The contributions add up to "
      "the covariance analysis's total to a relative {:.2g} (rounding: the sum is exact for the "
      "linear model). {}</p>\n",
      EscapeHtml(b.filter()), b.step_samples(), b.sources_size(), b.max_relative_sum_error(),
      EscapeHtml(b.verdict()));
  html += "<h2>Contributions against time</h2>\n<div class=\"grid\">\n";
  for (const Group& g : Groups()) html += StackedFigure(b, g);
  html += "</div>\n<h2>Top sources</h2>\n";
  for (const Group& g : Groups()) html += CheckpointTable(b, g);
  html += "<h2>Monte-Carlo check</h2>\n" + CheckTable(b);
  if (b.unrepresented_size() > 0) {
    html += "<h2>Terms the linear model leaves out</h2>\n<ul>\n";
    for (const std::string& u : b.unrepresented()) html += "<li>" + EscapeHtml(u) + "</li>\n";
    html += "</ul>\n";
  }
  return html + "</body>\n</html>\n";
}

}  // namespace driftlab::app
