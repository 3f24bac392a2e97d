// calibration_job.h: the recordings' CSV tables: reading (header, separators, selected columns
// by name) and the rate columns with their units, for `driftlab calibrate`, `driftlab allan` and
// the gRPC Calibration service.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <string_view>

#include "driftlab/app/calibration_job.h"
#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "text.h"

namespace driftlab::app {
namespace {

// Fewest samples with two overlapping second differences at tau = 1 / rate (n + 1 - 2m >= 2 for
// m = 1), the least the overlapping estimator can average (allan.h).
constexpr size_t kMinAllanSamples = 3;

const std::vector<std::string> kImuCsvColumns = {"omega_x_rad_per_s", "omega_y_rad_per_s",
                                                 "omega_z_rad_per_s", "f_x_m_per_s2",
                                                 "f_y_m_per_s2",      "f_z_m_per_s2"};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// Splits at `sep` into trimmed views of `line` (no allocation when `fields` has capacity).
void SplitInto(std::string_view line, char sep, std::vector<std::string_view>* fields) {
  fields->clear();
  size_t start = 0;
  while (true) {
    const size_t end = line.find(sep, start);
    fields->push_back(Trim(line.substr(start, end == std::string_view::npos ? end : end - start)));
    if (end == std::string_view::npos) return;
    start = end + 1;
  }
}

std::vector<std::string> Split(std::string_view line, char sep) {
  std::vector<std::string_view> views;
  SplitInto(line, sep, &views);
  return {views.begin(), views.end()};
}

// The reader behind both ReadNumericCsv overloads; `selected` empty = every column.
NumericTable ReadCsv(const std::string& path, const std::vector<std::string>* selected,
                     const std::string& columns_field) {
  std::ifstream in = OpenInputFile(path, kMaxRecordingFileBytes, "DATA");
  NumericTable table;
  std::string line;
  size_t line_no = 0;
  std::vector<std::string_view> fields;
  std::vector<std::string> header;
  std::vector<size_t> take;  // header index of each kept column
  bool have_header = false;
  bool pending_data = false;  // the first line was data (no header)
  const auto where = [&] { return fmt::format("{}:{}", path, line_no + 1); };
  while (ReadLine(in, &line, where())) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    SplitInto(t, ',', &fields);
    bool numeric = true;
    for (std::string_view f : fields) {
      double v = 0.0;
      numeric = numeric && ParseWholeNumber(f, &v);
    }
    if (numeric && selected == nullptr) {
      for (size_t i = 0; i < fields.size(); ++i) header.push_back(fmt::format("column{}", i + 1));
      pending_data = true;
    } else {
      header.assign(fields.begin(), fields.end());
    }
    have_header = true;
    break;
  }
  if (header.size() > kMaxCsvColumns) {
    throw SpecError(fmt::format("{}:{}", path, line_no), fmt::format("{} columns", header.size()),
                    fmt::format("at most {} columns", kMaxCsvColumns));
  }
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i].size() > kMaxCsvColumnNameBytes) {
      throw SpecError(fmt::format("{}:{}: column {}", path, line_no, i + 1), "'" + header[i] + "'",
                      fmt::format("a column name of at most {} bytes", kMaxCsvColumnNameBytes));
    }
    for (size_t j = 0; j < i; ++j) {
      if (header[i] == header[j]) {
        throw SpecError(fmt::format("{}:{}: column {}", path, line_no, i + 1),
                        "'" + header[i] + "' (also column " + std::to_string(j + 1) + ")",
                        "distinct column names");
      }
    }
  }
  if (!have_header) {
    throw SpecError("DATA", "'" + path + "' (empty)", "a header row and numeric rows");
  }
  if (selected == nullptr) {
    for (size_t i = 0; i < header.size(); ++i) take.push_back(i);
  } else {
    for (const std::string& name : *selected) {
      const auto it = std::find(header.begin(), header.end(), name);
      if (it == header.end()) {
        throw SpecError(columns_field, "'" + name + "'",
                        "a column of " + path + ": " + Join(header, ", "));
      }
      take.push_back(static_cast<size_t>(it - header.begin()));
    }
  }
  for (size_t i : take) table.columns.push_back(header[i]);
  const auto parse_row = [&](size_t row_line) {
    if (fields.size() != header.size()) {
      throw SpecError(fmt::format("{}:{}", path, row_line),
                      fmt::format("{} columns; expected {} ({} fields where the header has {} "
                                  "fields: {})",
                                  fields.size(), header.size(), fields.size(), header.size(),
                                  Join(header, ", ")),
                      0);
    }
    for (size_t i : take) {
      double value = 0.0;
      if (!ParseWholeNumber(fields[i], &value) || !std::isfinite(value)) {
        throw SpecError(fmt::format("{}:{}: column '{}'", path, row_line, header[i]),
                        "'" + std::string(fields[i]) + "'", "a finite number");
      }
      table.values.push_back(value);
    }
  };
  if (pending_data) parse_row(line_no);
  while (ReadLine(in, &line, where())) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    SplitInto(t, ',', &fields);
    parse_row(line_no);
  }
  return table;
}

bool IsTimeColumn(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name == "t" || name.rfind("t_", 0) == 0 || name.rfind("time", 0) == 0;
}

// Rates, or increments of them.
bool AcceptedDimension(Dimension d) {
  return d == dims::kAngularRate || d == dims::kAcceleration || d == dims::kAngle ||
         d == dims::kVelocity;
}

constexpr const char* kAllowedUnits =
    "an angular rate (rad/s, deg/s, deg/h), an acceleration (m/s^2, g, mg, ug) or an increment "
    "(rad, deg, m/s)";

void SetUnit(RateColumn* column, const std::string& text, const Unit& unit) {
  column->unit = text;
  column->gyro = unit.dimension.angle2 != 0;
  column->increment = unit.dimension == dims::kAngle || unit.dimension == dims::kVelocity;
}

// Unit from the name's suffix: the longest tail of '_'-separated words that parses as a unit of
// an accepted dimension ("per" = '/'). Returns false if no tail does.
// Tails are built from the end, one word at a time, and no longer than a unit text may be
// (kMaxUnitTextBytes), so the search is linear in the name's length.
bool UnitFromName(RateColumn* column) {
  const std::vector<std::string> words = Split(column->name, '_');
  std::string tail;
  bool found = false;
  for (size_t first = words.size(); first-- > 1;) {
    const std::string word = words[first] == "per" ? std::string("/") : words[first];
    tail = tail.empty() ? word : word + " " + tail;
    if (tail.size() > kMaxUnitTextBytes) break;
    try {
      const Unit unit = ParseUnit(tail, column->name);
      if (AcceptedDimension(unit.dimension)) {
        SetUnit(column, tail, unit);  // a longer tail found later replaces it
        found = true;
      }
    } catch (const SpecError&) {
      // Not a unit: try a longer tail.
    }
  }
  return found;
}

}  // namespace

NumericTable ReadNumericCsv(const std::string& path) { return ReadCsv(path, nullptr, ""); }

NumericTable ReadNumericCsv(const std::string& path, const std::vector<std::string>& columns,
                            const std::string& columns_field) {
  return ReadCsv(path, &columns, columns_field);
}

std::vector<RateColumn> SelectRateColumns(const NumericTable& table,
                                          const std::vector<std::string>& names,
                                          const std::string& unit, double rate_hz,
                                          const std::string& data_name,
                                          const std::string& columns_field,
                                          const std::string& unit_field) {
  const size_t width = table.columns.size();
  if (width == 0 || table.values.size() % width != 0) {
    throw SpecError("data",
                    fmt::format("{} values in rows of {} columns", table.values.size(), width), 0);
  }
  const auto find = [&](const std::string& name) -> long {
    const auto it = std::find(table.columns.begin(), table.columns.end(), name);
    return it == table.columns.end() ? -1 : static_cast<long>(it - table.columns.begin());
  };
  std::vector<std::pair<std::string, size_t>> chosen;
  if (!names.empty()) {
    for (const std::string& name : names) {
      const long index = find(name);
      if (index < 0) {
        throw SpecError(columns_field, name.empty() ? "''" : "'" + name + "'",
                        "a column of " + data_name + ": " + Join(table.columns, ", "));
      }
      chosen.emplace_back(name, static_cast<size_t>(index));
    }
  } else {
    const bool imu = std::all_of(kImuCsvColumns.begin(), kImuCsvColumns.end(),
                                 [&](const std::string& n) { return find(n) >= 0; });
    for (size_t i = 0; i < width; ++i) {
      const std::string& name = table.columns[i];
      const bool take = imu ? std::find(kImuCsvColumns.begin(), kImuCsvColumns.end(), name) !=
                                  kImuCsvColumns.end()
                            : !IsTimeColumn(name);
      if (take) chosen.emplace_back(name, i);
    }
    if (chosen.empty()) {
      throw SpecError("data", data_name + " (only a time column)",
                      "at least one column besides the time column");
    }
  }
  std::optional<Unit> common;
  if (!unit.empty()) {
    common = ParseUnit(unit, unit_field);
    if (!AcceptedDimension(common->dimension)) {
      throw SpecError(unit_field, "'" + unit + "' (" + DimensionName(common->dimension) + ")",
                      kAllowedUnits);
    }
  }
  const size_t rows = table.rows();
  std::vector<RateColumn> out;
  for (const auto& [name, index] : chosen) {
    RateColumn column;
    column.name = name;
    if (common) {
      SetUnit(&column, unit, *common);
    } else if (!UnitFromName(&column)) {
      throw SpecError(
          unit_field, "missing",
          fmt::format("a unit for column '{}' of {}: its name has no unit suffix (such as "
                      "_rad_per_s, _deg_per_s, _deg_per_h, _m_per_s2, _g, _mg); give {} as {}",
                      name, data_name, unit_field, kAllowedUnits));
    }
    const Unit parsed = ParseUnit(column.unit, unit_field);
    const double to_si = parsed.si_factor * (column.increment ? rate_hz : 1.0);
    if (rows < kMinAllanSamples) {
      throw SpecError(fmt::format("{}: column '{}'", data_name, name),
                      fmt::format("{} samples", rows),
                      fmt::format("at least {} samples (two overlapping second differences at "
                                  "tau = 1 / rate)",
                                  kMinAllanSamples));
    }
    column.samples.resize(rows);
    for (size_t r = 0; r < rows; ++r) {
      const double v = table.values[r * width + index];
      if (!std::isfinite(v)) {
        throw SpecError(fmt::format("{}: row {} column '{}'", data_name, r + 1, name),
                        fmt::format("{}", v), "a finite number");
      }
      column.samples[r] = v * to_si;
    }
    out.push_back(std::move(column));
  }
  return out;
}

}  // namespace driftlab::app
