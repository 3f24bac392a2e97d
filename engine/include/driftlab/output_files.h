// Writing output files safely (DESIGN.md invariant 10): every file driftlab writes
// (results, reports, CSV data, JUnit XML, models) goes to a temporary file in the target's
// directory, is flushed to disk (fsync) and renamed over the target, so that a reader never sees
// half a file and no partial file survives a failure; and a target that exists but is not a
// regular file (a symbolic link, a device such as /dev/null, a directory, a FIFO) is never
// replaced: that is refused.
#pragma once

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace driftlab {

// An output could not be written (disk full, permissions, ...): an I/O error, not bad input.
// One line: "FIELD: cannot write 'PATH': what (system reason)".
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `path` in single quotes for a message, at most about max_bytes bytes of it (MessageText): a
// longer path keeps its start and its file name (the name's last max_bytes / 2 bytes when the name
// alone is longer), with " ... " between them, each cut at a UTF-8 character boundary.
std::string QuotedPath(const std::filesystem::path& path, size_t max_bytes);

// A SpecError value made of `text` with each "{}" replaced by the next of `paths`, quoted and
// shortened in the middle (QuotedPath) so that the value fits kMaxMessageValueBytes: the paths
// share what the rest of the text leaves (at least 32 bytes each), and the text after them (an
// OS reason, say) is not cut off.
std::string PathsInMessage(std::string_view text, const std::vector<std::filesystem::path>& paths);

// Throws SpecError(field, "'PATH' (a symbolic link)", "a new file or a regular file to replace")
// when `path` exists and is not a regular file. For checking command-line outputs before the work
// starts. (A missing directory is an I/O error when the file is written: OutputError.)
void CheckOutputPath(const std::filesystem::path& path, const std::string& field);

// A file a command reads or writes and the option or argument that names it ("--out", "JOB").
struct CommandPath {
  std::filesystem::path path;
  std::string option;
};

// Refuses an output that would replace one of the command's inputs or another of its outputs:
// files are compared by device and inode, so another spelling ("./x", "d/../x"), a symbolic link
// or a hard link to the same file matches. An output that exists is identified by its own inode;
// one that does not exist yet by its directory's device and inode and its name (the file it would
// be created as). Inputs that do not exist are skipped (their reader reports them). Throws
// SpecError(output option, "'PATH' (the same file as INPUT_OPTION 'INPUT')", ...) for the first
// clash, in the order of `outputs`.
void CheckOutputsApart(const std::vector<CommandPath>& inputs,
                       const std::vector<CommandPath>& outputs);

// Checks, before the work, that a file can be created where `path` would be written, by creating
// and removing a temporary file in its directory, or, with `creates_directories` and a directory
// that does not exist yet, in its nearest existing ancestor (where the writer would create the
// missing ones). Throws SpecError(field, "'PATH' (cannot create a file in 'DIR': reason)", ...).
void CheckOutputWritable(const std::filesystem::path& path, const std::string& field,
                         bool creates_directories = false);

// One output file being written. Construction checks the target (CheckOutputPath) and creates
// the temporary file beside it; Commit() makes it the target; destruction without Commit() removes
// the temporary. I/O errors are OutputError; a target that is not a regular file is SpecError.
class OutputFile {
 public:
  OutputFile(const std::filesystem::path& path, const std::string& field);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // The temporary file's stream (fully buffered with the given buffer, if any).
  std::FILE* stream() { return file_; }
  void Write(std::string_view data);
  // Checks the stream, fsyncs, closes and renames the temporary over the target (then fsyncs the
  // directory). Throws OutputError on any failure (the temporary is removed then).
  void Commit();

  const std::filesystem::path& path() const { return path_; }

 private:
  [[noreturn]] void Fail(const std::string& what, int error_number);

  std::filesystem::path path_;
  std::filesystem::path temporary_;
  std::string field_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// OutputFile for a whole content at once.
void WriteOutputFile(const std::filesystem::path& path, std::string_view content,
                     const std::string& field);

}  // namespace driftlab
