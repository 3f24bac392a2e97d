// The CLI's shared option parsing and file outputs (commands.h).
#include <fmt/format.h>

#include <charconv>
#include <cstdio>

#include "commands.h"
#include "driftlab/output_files.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {

uint64_t ParseUnsignedOption(const std::string& option, const std::string& text, uint64_t min,
                             uint64_t max) {
  uint64_t value = 0;
  const char* end = text.data() + text.size();
  const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (!digits || ec != std::errc() || ptr != end || value < min || value > max) {
    throw CLI::ValidationError(
        option, fmt::format("{} is not allowed; allowed: an integer from {} to {} (decimal digits)",
                            text.empty() ? std::string("an empty value")
                                         : "'" + MessageText(text, 40) + "'",
                            min, max));
  }
  return value;
}

int WriteOutputText(const std::string& path, std::string_view text, const std::string& option) {
  try {
    WriteOutputFile(path, text, option);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  } catch (const OutputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  fmt::print("wrote {}\n", path);
  return kExitOk;
}

uint64_t MemoryLimitBytes(double gigabytes) {
  if (!(gigabytes >= 0.0) || gigabytes > 1e6) {
    throw SpecError("--max-memory-gb", fmt::format("{}", gigabytes), "0 (no limit) to 1e6 GB");
  }
  return static_cast<uint64_t>(gigabytes * 1e9);
}

void CheckCommandOutputs(const std::vector<CommandPath>& inputs,
                         const std::vector<CommandPath>& outputs, bool creates_directories) {
  const auto given = [](const std::vector<CommandPath>& paths) {
    std::vector<CommandPath> out;
    for (const CommandPath& p : paths) {
      if (!p.path.empty()) out.push_back(p);
    }
    return out;
  };
  const std::vector<CommandPath> given_outputs = given(outputs);
  CheckOutputsApart(given(inputs), given_outputs);
  for (const CommandPath& output : given_outputs) {
    CheckOutputPath(output.path, output.option);
    CheckOutputWritable(output.path, output.option, creates_directories);
  }
}

}  // namespace driftlab::cli
