// Shared by CLI tests (output_paths_cli_test.cc, simulate_run_cli_test.cc): the child-process
// runner's names (support/cli_runner.h) and writing a small file, in the namespace those tests'
// helpers live in, so that in a unity batch they are found before any other file's.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli_runner.h"

namespace driftlab::cli_test {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::Result;
using testing::RunDriftlab;
using testing::Scratch;

// Writes `content` to `path` (bytes as given, replacing the file); returns `path`.
inline fs::path Write(const fs::path& path, const std::string& content) {
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

}  // namespace driftlab::cli_test
