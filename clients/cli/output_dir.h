// The set of files `simulate` and `export` write into one output directory, written as a set
// (DESIGN.md invariant 10): every file goes first into a hidden temporary directory inside the
// output directory, made before the work starts (which also proves the directory writable); once
// all are complete they are renamed into place, each rename atomic. On an error, an exception or
// Ctrl-C the temporary directory is removed (with the output directory itself when this command
// created it), so no temporary file and no incomplete set of files is left beside older ones.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "driftlab/output_files.h"

namespace driftlab::cli {

class OutputDirectory {
 public:
  // `dir` (option `option`) receives the files `names`. Checks, before any work: no file of the
  // set is one of `inputs` (CheckOutputsApart, by device and inode), an existing file of the set is
  // a regular file, `dir` is a directory or can be created; then creates `dir` (with its parents)
  // and the temporary directory inside it. Throws SpecError naming `option`.
  OutputDirectory(const std::filesystem::path& dir, const std::string& option,
                  const std::vector<std::string>& names, const std::vector<CommandPath>& inputs);
  // Removes the temporary directory unless committed (and the directories this object created).
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  // Where file `name` (one of `names`) is written until Commit, in directory().
  std::filesystem::path Path(const std::string& name) const;
  const std::filesystem::path& directory() const { return temporary_; }
  // Renames every file of the set that was written into `dir` and removes the temporary directory.
  // Throws OutputError on an I/O error (a target that is no longer a regular file included).
  void Commit();

 private:
  void RemoveTemporary() noexcept;

  std::filesystem::path dir_;
  std::string option_;
  std::vector<std::string> names_;
  std::filesystem::path temporary_;
  std::vector<std::filesystem::path> created_;  // directories this object made, deepest last
  bool committed_ = false;
};

}  // namespace driftlab::cli
