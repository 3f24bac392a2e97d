// Safe output files (output_files.h): temporary file beside the target, fsync, rename.
#include "driftlab/output_files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <vector>

#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

std::string KindOf(mode_t mode) {
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::filesystem::path DirectoryOf(const std::filesystem::path& path) {
  return path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
}

bool IsUtf8Continuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

}  // namespace

std::string QuotedPath(const std::filesystem::path& path, size_t max_bytes) {
  const std::string text = path.string();
  if (text.size() <= max_bytes) return "'" + MessageText(text, max_bytes) + "'";
  constexpr std::string_view kGap = " ... ";
  const std::string name = path.filename().string();
  size_t name_start = name.size() > max_bytes / 2 ? name.size() - max_bytes / 2 : 0;
  while (name_start < name.size() && IsUtf8Continuation(name[name_start])) ++name_start;
  const std::string name_end = name.substr(name_start);
  size_t head =
      max_bytes > name_end.size() + kGap.size() ? max_bytes - name_end.size() - kGap.size() : 0;
  while (head > 0 && IsUtf8Continuation(text[head])) --head;
  return "'" + MessageText(text.substr(0, head), head) + std::string(kGap) +
         MessageText(name_end, name_end.size()) + "'";
}

std::string PathsInMessage(std::string_view text, const std::vector<std::filesystem::path>& paths) {
  constexpr std::string_view kSlot = "{}";
  // Each "{}" becomes a path's two quotes: the text's other bytes are its size.
  const size_t other_bytes = text.size();
  const size_t left = kMaxMessageValueBytes > other_bytes ? kMaxMessageValueBytes - other_bytes : 0;
  const size_t each = std::max<size_t>(32, paths.empty() ? 0 : left / paths.size());
  std::string out;
  size_t from = 0;
  for (const std::filesystem::path& path : paths) {
    const size_t slot = text.find(kSlot, from);
    if (slot == std::string_view::npos) break;
    out.append(text.substr(from, slot - from));
    out += QuotedPath(path, each);
    from = slot + kSlot.size();
  }
  out.append(text.substr(from));
  return out;
}

void CheckOutputPath(const std::filesystem::path& path, const std::string& field) {
  if (path.empty() || !path.has_filename()) {
    throw SpecError(field, "'" + path.string() + "'", "a file path");
  }
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode)) {
      throw SpecError(field, PathsInMessage("{} (" + KindOf(st.st_mode) + ")", {path}),
                      "a new file or a regular file to replace (driftlab never writes over "
                      "anything else)");
    }
  } else if (errno != ENOENT) {
    throw SpecError(field, PathsInMessage(std::string("{} (") + std::strerror(errno) + ")", {path}),
                    "a writable path");
  }
}

namespace {

// What a path names: an existing file's device and inode, or, for a file that does not exist yet,
// its directory's device and inode and its name; a directory that does not exist either leaves
// the lexically normalised absolute path.
struct FileIdentity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string name;  // of a file that does not exist: its name in that directory (or full path)

  bool operator==(const FileIdentity& other) const {
    return exists == other.exists && device == other.device && inode == other.inode &&
           name == other.name;
  }
};

FileIdentity IdentityOf(const std::filesystem::path& path) {
  FileIdentity id;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.device = st.st_dev;
    id.inode = st.st_ino;
    return id;
  }
  if (::stat(DirectoryOf(path).c_str(), &st) == 0) {
    id.device = st.st_dev;
    id.inode = st.st_ino;
    id.name = path.filename().string();
    return id;
  }
  std::error_code error;
  id.name = std::filesystem::weakly_canonical(std::filesystem::absolute(path, error), error)
                .lexically_normal()
                .string();
  return id;
}

}  // namespace

void CheckOutputsApart(const std::vector<CommandPath>& inputs,
                       const std::vector<CommandPath>& outputs) {
  std::vector<FileIdentity> input_ids;
  for (const CommandPath& input : inputs) input_ids.push_back(IdentityOf(input.path));
  std::vector<FileIdentity> output_ids;
  for (const CommandPath& output : outputs) {
    const FileIdentity id = IdentityOf(output.path);
    const std::string allowed =
        "a path that names none of the command's inputs and no other output (compared by device "
        "and inode)";
    for (size_t i = 0; i < inputs.size(); ++i) {
      if (input_ids[i].exists && id == input_ids[i]) {
        throw SpecError(
            output.option,
            PathsInMessage("{} (the same file as " + inputs[i].option + " {}, an input)",
                           {output.path, inputs[i].path}),
            allowed);
      }
    }
    for (size_t j = 0; j < output_ids.size(); ++j) {
      if (id == output_ids[j]) {
        throw SpecError(
            output.option,
            PathsInMessage("{} (the same file as " + outputs[j].option + " {}, another output)",
                           {output.path, outputs[j].path}),
            allowed);
      }
    }
    output_ids.push_back(id);
  }
}

void CheckOutputWritable(const std::filesystem::path& path, const std::string& field,
                         bool creates_directories) {
  std::filesystem::path dir = std::filesystem::absolute(DirectoryOf(path)).lexically_normal();
  struct stat st {};
  while (creates_directories && ::stat(dir.c_str(), &st) != 0 && errno == ENOENT &&
         dir.has_relative_path()) {
    dir = dir.parent_path();
  }
  std::string reason;
  if (::stat(dir.c_str(), &st) != 0) {
    reason = std::strerror(errno);
  } else if (!S_ISDIR(st.st_mode)) {
    reason = "not a directory";
  } else {
    std::string pattern = (dir / ".driftlab-write-check-XXXXXX").string();
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    const int fd = ::mkstemp(name.data());
    if (fd >= 0) {
      ::close(fd);
      ::unlink(name.data());
      return;
    }
    reason = std::strerror(errno);
  }
  throw SpecError(field,
                  PathsInMessage("{} (cannot create a file in {}: " + reason + ")", {path, dir}),
                  "a path in a directory where files can be created");
}

OutputFile::OutputFile(const std::filesystem::path& path, const std::string& field)
    : path_(path), field_(field) {
  CheckOutputPath(path, field);
  std::string pattern =
      (DirectoryOf(path) / ("." + path.filename().string() + ".tmp-XXXXXX")).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) Fail("cannot create a temporary file beside it", errno);
  temporary_ = name.data();
  // mkstemp makes the file 0600; outputs are ordinary files (0666 less the umask).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd, 0666 & ~mask);
  file_ = ::fdopen(fd, "w");
  if (file_ == nullptr) {
    const int error_number = errno;
    ::close(fd);
    Fail("cannot open the temporary file", error_number);
  }
}

OutputFile::~OutputFile() {
  if (file_ != nullptr) std::fclose(file_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
}

void OutputFile::Fail(const std::string& what, int error_number) {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!temporary_.empty()) ::unlink(temporary_.c_str());
  temporary_.clear();
  throw OutputError(
      MessageText(field_, kMaxMessageFieldBytes) + ": cannot write " +
      QuotedPath(path_, kMaxMessageValueBytes) + ": " + what +
      (error_number != 0 ? std::string(" (") + std::strerror(error_number) + ")" : std::string()));
}

void OutputFile::Write(std::string_view data) {
  if (std::fwrite(data.data(), 1, data.size(), file_) != data.size()) Fail("write error", errno);
}

void OutputFile::Commit() {
  if (std::fflush(file_) != 0 || std::ferror(file_) != 0) Fail("write error", errno);
  if (::fsync(::fileno(file_)) != 0 && errno != EINVAL) Fail("fsync failed", errno);
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) Fail("close failed", errno);
  // The target may have been replaced by something else since the check: refuse it then too.
  struct stat st {};
  if (::lstat(path_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    Fail("it became " + KindOf(st.st_mode), 0);
  }
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) Fail("rename failed", errno);
  committed_ = true;
  // The rename is durable once the directory is on disk.
  const int dir = ::open(DirectoryOf(path_).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

void WriteOutputFile(const std::filesystem::path& path, std::string_view content,
                     const std::string& field) {
  OutputFile file(path, field);
  file.Write(content);
  file.Commit();
}

}  // namespace driftlab
