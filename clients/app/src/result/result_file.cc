#include "driftlab/app/result_file.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "driftlab/app/json_syntax.h"
#include "driftlab/input_files.h"
#include "driftlab/output_files.h"
#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

namespace util = google::protobuf::util;

// protobuf's status text is several lines (reason, context, caret); one line for our errors.
std::string OneLine(const util::Status& status) {
  std::string text(status.message());
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

// protobuf 3.21 prints the double -0.0 as the JSON number -0, which its parser reads back as
// +0.0 (as an integer); -0.0 reads back with its sign. Rewrites every number token -0 outside
// strings to -0.0 so that a written result reads back to the same bits.
std::string KeepNegativeZeros(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  bool in_string = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char ch = json[i];
    out += ch;
    if (in_string) {
      if (ch == '\\' && i + 1 < json.size()) {
        out += json[++i];
      } else if (ch == '"') {
        in_string = false;
      }
    } else if (ch == '"') {
      in_string = true;
    } else if (ch == '-' && i + 1 < json.size() && json[i + 1] == '0') {
      const char next = i + 2 < json.size() ? json[i + 2] : ' ';
      const bool number_goes_on =
          next == '.' || next == 'e' || next == 'E' || (next >= '0' && next <= '9');
      if (!number_goes_on) {
        out += "0.0";
        ++i;
      }
    }
  }
  return out;
}

void Check(bool ok, const std::string& field, double value, const std::string& allowed) {
  if (!ok) throw SpecError(field, fmt::format("{}", value), allowed);
}

// Not NaN and not infinite.
void CheckFinite(const std::string& field, double value) {
  Check(std::isfinite(value), field, value, "a finite number");
}

void CheckNonNegative(const std::string& field, double value) {
  Check(std::isfinite(value) && value >= 0, field, value, "a finite number >= 0");
}

// A confidence interval [low, high]: 0 <= low <= high, low finite, high finite or +Infinity.
void CheckInterval(const std::string& prefix, const std::string& low_name, double low,
                   const std::string& high_name, double high) {
  CheckNonNegative(prefix + low_name, low);
  Check(!std::isnan(high) && high >= low, prefix + high_name, high,
        fmt::format("{} >= {} = {} (may be Infinity)", high_name, low_name, low));
}

std::string ComponentName(int component) {
  return v1::ErrorComponent_Name(static_cast<v1::ErrorComponent>(component));
}

template <typename ComponentList>
void CheckComponentOrder(const std::string& path, const ComponentList& components) {
  if (components.size() != kErrorComponentCount) {
    throw SpecError(path + ".components", fmt::format("{} entries", components.size()),
                    fmt::format("exactly {} entries, one per ErrorComponent in enum order",
                                kErrorComponentCount));
  }
  for (int i = 0; i < kErrorComponentCount; ++i) {
    if (components[i].component() != i + 1) {
      throw SpecError(fmt::format("{}.components[{}].component", path, i),
                      ComponentName(components[i].component()),
                      ComponentName(i + 1) + " (components in ErrorComponent order)");
    }
  }
}

// b >= a for percentiles of one sample, allowing 4 ulp: the interpolation x_k + f (x_k+1 - x_k)
// of one percentile may round a few ulp above the order statistic x_k+1 that bounds the next.
bool NotBelow(double b, double a) {
  return b >= a - 4 * std::numeric_limits<double>::epsilon() * std::abs(a);
}

// t_s of a list of epochs or checkpoints: finite, >= 0, strictly increasing.
void CheckTime(const std::string& list, int i, double t_s, double previous_t_s) {
  const std::string field = fmt::format("{}[{}].t_s", list, i);
  CheckNonNegative(field, t_s);
  if (i > 0) {
    Check(t_s > previous_t_s, field, t_s,
          fmt::format("> {}[{}].t_s = {} (strictly increasing)", list, i - 1, previous_t_s));
  }
}

// With one run the sample sigma and its interval are undefined and NaN (result.proto).
void ValidateEpoch(const v1::EpochStatistics& epoch, const std::string& path, bool single_run) {
  CheckComponentOrder(path, epoch.components());
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const v1::ComponentStatistics& s = epoch.components(c);
    const std::string prefix = fmt::format("{}.components[{}].", path, c);
    CheckFinite(prefix + "mean", s.mean());
    if (single_run) {
      for (const auto& [name, value] : {std::pair<const char*, double>{"std", s.std()},
                                        {"std_ci95_low", s.std_ci95_low()},
                                        {"std_ci95_high", s.std_ci95_high()}}) {
        Check(std::isnan(value), prefix + name, value, "NaN (undefined for run_count = 1)");
      }
    } else {
      CheckNonNegative(prefix + "std", s.std());
      CheckInterval(prefix, "std_ci95_low", s.std_ci95_low(), "std_ci95_high", s.std_ci95_high());
    }
    CheckNonNegative(prefix + "rms", s.rms());
    CheckInterval(prefix, "rms_ci95_low", s.rms_ci95_low(), "rms_ci95_high", s.rms_ci95_high());
  }
}

void ValidateCheckpoint(const v1::Checkpoint& checkpoint, const std::string& path,
                        const v1::JobResult& result) {
  CheckComponentOrder(path, checkpoint.components());
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const v1::ComponentPercentiles& p = checkpoint.components(c);
    const std::string prefix = fmt::format("{}.components[{}].", path, c);
    const std::pair<const char*, double> ordered[] = {{"p50", p.p50()},
                                                      {"p68", p.p68()},
                                                      {"p95", p.p95()},
                                                      {"p99", p.p99()},
                                                      {"max_abs", p.max_abs()}};
    CheckNonNegative(prefix + "p50", p.p50());
    for (size_t k = 1; k < std::size(ordered); ++k) {
      const std::string field = prefix + ordered[k].first;
      CheckNonNegative(field, ordered[k].second);
      Check(NotBelow(ordered[k].second, ordered[k - 1].second), field, ordered[k].second,
            fmt::format(">= {} = {}", ordered[k - 1].first, ordered[k - 1].second));
    }
  }
  CheckNonNegative(path + ".cep50_m", checkpoint.cep50_m());
  CheckNonNegative(path + ".cep95_m", checkpoint.cep95_m());
  Check(NotBelow(checkpoint.cep95_m(), checkpoint.cep50_m()), path + ".cep95_m",
        checkpoint.cep95_m(), fmt::format(">= cep50_m = {}", checkpoint.cep50_m()));
  CheckNonNegative(path + ".drms2_m", checkpoint.drms2_m());

  const int runs = checkpoint.runs_size();
  if (runs != 0 && runs != static_cast<int>(result.run_count())) {
    throw SpecError(
        path + ".runs", fmt::format("{} entries", runs),
        fmt::format("none or one per run of the file (run_count = {})", result.run_count()));
  }
  for (int r = 0; r < runs; ++r) {
    const v1::RunValues& run = checkpoint.runs(r);
    const std::string prefix = fmt::format("{}.runs[{}].", path, r);
    // With exactly run_count strictly increasing indices, index r is first_run + r.
    const uint64_t expected = uint64_t{result.first_run()} + r;
    if (run.run_index() != expected) {
      throw SpecError(
          prefix + "run_index", std::to_string(run.run_index()),
          fmt::format("{} (first_run + {}; run indices strictly increasing)", expected, r));
    }
    if (run.values_size() != kErrorComponentCount) {
      throw SpecError(
          prefix + "values", fmt::format("{} values", run.values_size()),
          fmt::format("exactly {} values in ErrorComponent order", kErrorComponentCount));
    }
    for (int c = 0; c < kErrorComponentCount; ++c) {
      const std::string field = fmt::format("{}values[{}]", prefix, c);
      if (c + 1 >= v1::HORIZONTAL_POSITION_M) {
        CheckNonNegative(field, run.values(c));  // a distance
      } else {
        CheckFinite(field, run.values(c));
      }
    }
  }
}

}  // namespace

std::string ComponentKey(v1::ErrorComponent component) {
  std::string key = v1::ErrorComponent_Name(component);
  for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return key;
}

std::string ComponentUnit(v1::ErrorComponent component) {
  switch (component) {
    case v1::VELOCITY_NORTH_M_PER_S:
    case v1::VELOCITY_EAST_M_PER_S:
    case v1::VELOCITY_DOWN_M_PER_S:
      return "m/s";
    case v1::ROLL_DEG:
    case v1::PITCH_DEG:
    case v1::YAW_DEG:
      return "deg";
    default:
      return "m";
  }
}

void ValidateJobResult(const v1::JobResult& result) {
  Check(result.runs() >= 1, "runs", result.runs(), ">= 1");
  Check(result.run_count() >= 1, "run_count", result.run_count(), ">= 1");
  const uint64_t end = uint64_t{result.first_run()} + result.run_count();
  if (end > result.runs()) {
    throw SpecError("run_count", std::to_string(result.run_count()),
                    fmt::format("first_run + run_count <= runs = {} (first_run = {})",
                                result.runs(), result.first_run()));
  }
  if (result.epochs().empty()) throw SpecError("epochs", "", "at least one epoch (the final)");
  for (int i = 0; i < result.epochs_size(); ++i) {
    CheckTime("epochs", i, result.epochs(i).t_s(), i > 0 ? result.epochs(i - 1).t_s() : 0);
    ValidateEpoch(result.epochs(i), fmt::format("epochs[{}]", i), result.run_count() == 1);
  }
  if (result.checkpoints().empty()) {
    throw SpecError("checkpoints", "", "at least one checkpoint (the final epoch)");
  }
  for (int i = 0; i < result.checkpoints_size(); ++i) {
    CheckTime("checkpoints", i, result.checkpoints(i).t_s(),
              i > 0 ? result.checkpoints(i - 1).t_s() : 0);
    ValidateCheckpoint(result.checkpoints(i), fmt::format("checkpoints[{}]", i), result);
  }
  const double final_t_s = result.epochs().rbegin()->t_s();
  const int last = result.checkpoints_size() - 1;
  Check(result.checkpoints(last).t_s() == final_t_s, fmt::format("checkpoints[{}].t_s", last),
        result.checkpoints(last).t_s(),
        fmt::format("the final epoch's t_s = {} (the last checkpoint is the final epoch)",
                    final_t_s));

  const v1::Timings& timings = result.timings();
  CheckNonNegative("timings.wall_s", timings.wall_s());
  if (timings.has_cpu_s()) CheckNonNegative("timings.cpu_s", timings.cpu_s());
  CheckNonNegative("timings.samples_per_s", timings.samples_per_s());
  // Counts are summed when shards are merged (signed 64-bit in the engine): bounded here so that
  // no hand-edited file can overflow them. 2^62 samples is ~150 years at 1e9 samples/s.
  constexpr uint64_t kMaxResultSamples = uint64_t{1} << 62;
  if (timings.samples() > kMaxResultSamples) {
    throw SpecError("timings.samples", std::to_string(timings.samples()),
                    fmt::format("<= {} (2^62)", kMaxResultSamples));
  }

  const v1::MergeState& merge_counts = result.merge_state();
  for (int i = 0; i < merge_counts.nees_counts_size(); ++i) {
    // One NEES value per run and epoch at most.
    if (merge_counts.nees_counts(i) > result.run_count()) {
      throw SpecError(fmt::format("merge_state.nees_counts[{}]", i),
                      std::to_string(merge_counts.nees_counts(i)),
                      fmt::format("<= run_count = {} (one per run)", result.run_count()));
    }
  }

  const v1::MergeState& merge = result.merge_state();
  if (!merge.epochs().empty()) {
    if (merge.epochs_size() != result.epochs_size()) {
      throw SpecError("merge_state.epochs", fmt::format("{} entries", merge.epochs_size()),
                      fmt::format("none or one per epoch ({})", result.epochs_size()));
    }
    for (int i = 0; i < merge.epochs_size(); ++i) {
      const std::string path = fmt::format("merge_state.epochs[{}]", i);
      Check(merge.epochs(i).t_s() == result.epochs(i).t_s(), path + ".t_s", merge.epochs(i).t_s(),
            fmt::format("epochs[{}].t_s = {}", i, result.epochs(i).t_s()));
      CheckComponentOrder(path, merge.epochs(i).components());
    }
  }
}

std::string JobResultToJson(const v1::JobResult& result) {
  util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  // No always_print_primitive_fields: it makes protobuf build a tree of the whole message (about
  // 300 bytes per field: 650 MB for a 1000-run, 1 h, 1 s-epoch result); the fields that must be
  // printed when 0 are `optional` in result.proto.
  std::string json;
  const util::Status status = util::MessageToJsonString(result, &json, options);
  if (!status.ok()) throw SpecError("result", OneLine(status), 0);
  return KeepNegativeZeros(json);
}

v1::JobResult ParseJobResultJson(std::string_view json_text, std::string_view source) {
  v1::JobResult result;
  CheckJsonSyntax(json_text, source, "result JSON");
  const util::Status status = util::JsonStringToMessage(json_text, &result);
  if (!status.ok()) {
    throw SpecError(std::string(source), "invalid result JSON: " + OneLine(status), 0);
  }
  try {
    ValidateJobResult(result);
  } catch (const SpecError& e) {
    throw SpecError(std::string(source), e.what(), 0);
  }
  return result;
}

v1::JobResult ReadJobResult(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = ReadInputFile(path, kMaxResultFileBytes, name);
  return ParseJobResultJson(text, name);
}

void WriteJobResult(const std::filesystem::path& path, const v1::JobResult& result) {
  const std::string name = path.string();
  try {
    ValidateJobResult(result);
  } catch (const SpecError& e) {
    throw SpecError(name, std::string("refusing to write an invalid result: ") + e.what(), 0);
  }
  const std::string json = JobResultToJson(result);
  // A temporary file beside the target, synced and renamed over it (output_files.h): a reader
  // never sees half a file, and nothing but a regular file is replaced.
  WriteOutputFile(path, json, name);
}

}  // namespace driftlab::app
