// The `driftlab` commands, one file each. Every command file registers itself with a static
// RegisterCommand object: main.cc builds the CLI11 app from the registry (sorted by name, so the
// help text does not depend on link order) and runs the one subcommand given.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/output_files.h"

namespace driftlab::cli {

// Exit statuses shared by every command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // I/O or internal error (and `gate`: a regression)
inline constexpr int kExitBadJob = 2;   // invalid job file, data file or command line

// Declares one subcommand on `app` (options bound to state the closure owns) and returns the
// function that runs it after parsing, returning the exit status.
using AddCommand = std::function<std::function<int()>(CLI::App& app)>;

struct CommandEntry {
  std::string name;  // for ordering only
  AddCommand add;
};

// All registered commands (static registration from each command's file).
std::vector<CommandEntry>& CommandRegistry();

// Writes `text` to `path` safely (output_files.h: temporary file, fsync, rename; never over
// anything but a regular file) and prints "wrote PATH". Returns kExitOk, kExitBadJob when the
// target is refused (the message names `option`), or kExitFailure on an I/O error; errors on
// stderr. Every command's file output goes through it.
int WriteOutputText(const std::string& path, std::string_view text, const std::string& option);

// The checks of a command's output files before its work starts (DESIGN.md invariant 10): no
// output names one of the command's inputs or another of its outputs (CheckOutputsApart: by
// device and inode, whatever the spelling or link), each is a new file or a regular file to
// replace (CheckOutputPath), and its directory takes new files (CheckOutputWritable; with
// `creates_directories`, for writers that create missing directories, the nearest existing
// ancestor). Entries with an empty path (an option not given) are skipped. Throws SpecError naming
// the output's option (exit status 2).
void CheckCommandOutputs(const std::vector<CommandPath>& inputs,
                         const std::vector<CommandPath>& outputs, bool creates_directories = false);

// Unsigned integer options parsed strictly (CLI11 would wrap "-1" or 2^64 to 2^64 - 1 and skip an
// empty value): decimal digits only, within [min, max]; anything else is a one-line error naming
// the option, the value and the allowed range (exit 2).
uint64_t ParseUnsignedOption(const std::string& option, const std::string& text, uint64_t min,
                             uint64_t max);
template <typename T>
CLI::Option* AddUnsignedOption(CLI::App* command, const std::string& name, std::optional<T>* value,
                               const std::string& help, uint64_t min = 0,
                               uint64_t max = std::numeric_limits<T>::max()) {
  return command->add_option_function<std::string>(
      name,
      [name, value, min, max](const std::string& text) {
        *value = static_cast<T>(ParseUnsignedOption(name, text, min, max));
      },
      help);
}
template <typename T>
CLI::Option* AddUnsignedOption(CLI::App* command, const std::string& name, T* value,
                               const std::string& help, uint64_t min = 0,
                               uint64_t max = std::numeric_limits<T>::max()) {
  return command->add_option_function<std::string>(
      name,
      [name, value, min, max](const std::string& text) {
        *value = static_cast<T>(ParseUnsignedOption(name, text, min, max));
      },
      help);
}

// --max-memory-gb G as bytes (0 = no limit); SpecError for a negative or non-finite G.
uint64_t MemoryLimitBytes(double gigabytes);

struct RegisterCommand {
  RegisterCommand(std::string name, AddCommand add) {
    CommandRegistry().push_back({std::move(name), std::move(add)});
  }
};

}  // namespace driftlab::cli
