// Replays every saved fuzz input (fuzz/corpus/<target>/: the seeds; fuzz/regressions/<target>/:
// every input that once crashed, hung or leaked a target) through the same functions the libFuzzer
// executables call (fuzz/fuzz_targets.h), so the normal and the sanitizer builds check them
// without clang. A target refuses bad input with a SpecError, which it catches itself: any
// exception reaching the test is a failure, a crash ends the test, a hang hits ctest's timeout.
#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include "fuzz_targets.h"

namespace driftlab::fuzz {

// Test names and messages show the target's name.
void PrintTo(const FuzzTarget& target, std::ostream* out) { *out << target.name; }

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> FilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().filename() != "README.md") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void Replay(const FuzzTarget& target, const fs::path& file) {
  const std::string bytes = ReadBytes(file);
  try {
    target.function(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  } catch (const std::exception& e) {
    ADD_FAILURE() << file << ": " << e.what();
  } catch (...) {
    ADD_FAILURE() << file << ": an exception that is not a std::exception";
  }
}

class FuzzInputs : public ::testing::TestWithParam<FuzzTarget> {};

TEST_P(FuzzInputs, SeedCorpusIsPresentAndReplaysCleanly) {
  const fs::path dir = fs::path(DRIFTLAB_SOURCE_DIR) / "fuzz" / "corpus" / GetParam().name;
  const std::vector<fs::path> files = FilesIn(dir);
  EXPECT_FALSE(files.empty()) << "no seed inputs in " << dir;
  for (const fs::path& file : files) Replay(GetParam(), file);
}

TEST_P(FuzzInputs, EveryRegressionReplaysCleanly) {
  const fs::path dir = fs::path(DRIFTLAB_SOURCE_DIR) / "fuzz" / "regressions" / GetParam().name;
  for (const fs::path& file : FilesIn(dir)) Replay(GetParam(), file);
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzInputs, ::testing::ValuesIn(FuzzTargets()),
                         [](const ::testing::TestParamInfo<FuzzTarget>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace driftlab::fuzz
