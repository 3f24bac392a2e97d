// WriteOutputText and OutputPathUsable (commands.h): the CLI's file outputs.
#include <fmt/format.h>

#include <cstdio>

#include "commands.h"
#include "driftlab/output_files.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {

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

bool OutputPathUsable(const std::string& path, const std::string& option) {
  try {
    CheckOutputPath(path, option);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return false;
  }
  return true;
}

}  // namespace driftlab::cli
