// OutputDirectory (output_dir.h): a set of output files written beside each other atomically
// enough that no failure leaves a partial set.
#include "output_dir.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

namespace fs = std::filesystem;

}  // namespace

OutputDirectory::OutputDirectory(const fs::path& dir, const std::string& option,
                                 const std::vector<std::string>& names,
                                 const std::vector<CommandPath>& inputs)
    : dir_(dir), option_(option), names_(names) {
  if (dir.empty()) throw SpecError(option, "''", "a directory path");
  struct stat st {};
  if (::stat(dir.c_str(), &st) == 0 && !S_ISDIR(st.st_mode)) {
    throw SpecError(option, PathsInMessage("{} (not a directory)", {dir}),
                    "a directory, or a path where one can be created");
  }
  std::vector<CommandPath> outputs;
  for (const std::string& name : names) outputs.push_back({dir / name, option + " " + name});
  CheckOutputsApart(inputs, outputs);
  for (const CommandPath& output : outputs) CheckOutputPath(output.path, option);
  CheckOutputWritable(dir / names.front(), option, /*creates_directories=*/true);

  // The directories that do not exist yet, outermost first, created one by one (so that exactly
  // these are removed again on failure).
  std::vector<fs::path> missing;
  for (fs::path p = fs::absolute(dir).lexically_normal(); !p.empty() && p.has_relative_path();
       p = p.parent_path()) {
    if (::stat(p.c_str(), &st) == 0) break;
    missing.insert(missing.begin(), p);
  }
  for (const fs::path& p : missing) {
    if (::mkdir(p.c_str(), 0777) != 0 && errno != EEXIST) {
      const int error_number = errno;
      RemoveTemporary();
      throw SpecError(
          option,
          PathsInMessage(std::string("{} (cannot create {}: ") + std::strerror(error_number) + ")",
                         {dir, p}),
          "a directory, or a path where one can be created");
    }
    created_.push_back(p);
  }
  std::string pattern = (dir / ".driftlab-tmp-XXXXXX").string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  if (::mkdtemp(name.data()) == nullptr) {
    const int error_number = errno;
    RemoveTemporary();
    throw SpecError(option,
                    PathsInMessage(std::string("{} (cannot create a directory in it: ") +
                                       std::strerror(error_number) + ")",
                                   {dir}),
                    "a directory where files can be created");
  }
  temporary_ = name.data();
}

OutputDirectory::~OutputDirectory() {
  if (!committed_) RemoveTemporary();
}

fs::path OutputDirectory::Path(const std::string& name) const { return temporary_ / name; }

void OutputDirectory::Commit() {
  const auto fail = [this](const std::string& what, int error_number) {
    RemoveTemporary();
    throw OutputError(MessageText(option_, kMaxMessageFieldBytes) + ": cannot write " +
                      QuotedPath(dir_, kMaxMessageValueBytes) + ": " + what +
                      (error_number != 0 ? std::string(" (") + std::strerror(error_number) + ")"
                                         : std::string()));
  };
  // Every target is still absent or a regular file before the first one is replaced.
  for (const std::string& name : names_) {
    struct stat st {};
    if (::lstat((dir_ / name).c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      fail(QuotedPath(dir_ / name, kMaxMessageValueBytes) + " is no longer a regular file", 0);
    }
  }
  for (const std::string& name : names_) {
    const fs::path from = temporary_ / name;
    struct stat st {};
    if (::lstat(from.c_str(), &st) != 0) continue;  // not part of this run's set
    if (std::rename(from.c_str(), (dir_ / name).c_str()) != 0) fail("rename failed", errno);
  }
  committed_ = true;
  std::error_code ignored;
  fs::remove_all(temporary_, ignored);
  const int fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

void OutputDirectory::RemoveTemporary() noexcept {
  std::error_code ignored;
  if (!temporary_.empty()) fs::remove_all(temporary_, ignored);
  temporary_.clear();
  // The directories made for this set, innermost first, and only while empty.
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    if (::rmdir(it->c_str()) != 0) break;
  }
  created_.clear();
}

}  // namespace driftlab::cli
