// Messages about output paths (output_files.h): a long path is shortened in the middle, keeping its
// start and its file name, so that the OS reason after it always reaches the user.
#include "driftlab/output_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

namespace fs = std::filesystem;

TEST(QuotedPath, ShortPathIsWholeAndLongPathKeepsItsStartAndFileName) {
  EXPECT_EQ(QuotedPath("/tmp/out/result.json", 64), "'/tmp/out/result.json'");
  const std::string start = "/tmp/" + std::string(200, 'd');
  const std::string text = QuotedPath(fs::path(start) / "result.json", 64);
  EXPECT_EQ(text.size(), 64u + 2u);  // at most max_bytes of path text, and the two quotes
  EXPECT_EQ(text.rfind("'/tmp/ddd", 0), 0u) << text;
  EXPECT_NE(text.find(" ... result.json'"), std::string::npos) << text;
  // A file name longer than half the budget: its last 32 bytes.
  const std::string long_name = std::string(100, 'n') + ".json";
  const std::string cut = QuotedPath(fs::path("/tmp") / long_name, 64);
  EXPECT_NE(cut.find(" ... " + long_name.substr(long_name.size() - 32) + "'"), std::string::npos)
      << cut;
  // Never a UTF-8 character cut in two: "é" is 2 bytes, at the cut of the start.
  std::string accents = "/";
  for (int i = 0; i < 100; ++i) accents += "\xC3\xA9";
  const std::string utf8 = QuotedPath(fs::path(accents) / "r.json", 40);
  EXPECT_EQ(utf8.find("\\x"), std::string::npos) << utf8;
}

TEST(CheckOutputWritable, LongPathInAMissingDirectoryKeepsTheOsReason) {
  // Over 300 characters: a directory that does not exist (six levels of 48 characters, each
  // within NAME_MAX), then the file name.
  fs::path dir = fs::temp_directory_path() / ("driftlab_missing_" + std::to_string(::getpid()));
  for (char c = 'a'; c < 'g'; ++c) dir /= std::string(48, c);
  const fs::path path = dir / "result.json";
  ASSERT_GE(path.string().size(), 300u);
  ASSERT_FALSE(fs::exists(dir));
  try {
    CheckOutputWritable(path, "--out");
    FAIL() << "accepted " << path;
  } catch (const SpecError& e) {
    const std::string message = e.what();
    const std::string reason = std::string(": ") + std::strerror(ENOENT) + ")";
    const std::string tail =
        " is not allowed; allowed: a path in a directory where files can be "
        "created";
    // The value (before " is not allowed") ends with the OS reason, and was not cut.
    ASSERT_GE(message.size(), reason.size() + tail.size());
    EXPECT_EQ(message.substr(message.size() - tail.size()), tail) << message;
    EXPECT_EQ(message.substr(message.size() - tail.size() - reason.size(), reason.size()), reason)
        << message;
    EXPECT_EQ(message.find("bytes)"), std::string::npos) << message;
    EXPECT_NE(message.find("result.json'"), std::string::npos) << message;
    EXPECT_EQ(message.rfind("--out: '" + fs::temp_directory_path().string(), 0), 0u) << message;
  }
}

}  // namespace
}  // namespace driftlab
