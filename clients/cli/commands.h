// The `driftlab` commands, one file each. Every command file registers itself with a static
// RegisterCommand object: main.cc builds the CLI11 app from the registry (sorted by name, so the
// help text does not depend on link order) and runs the one subcommand given.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

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

// Refuses an output path before the work starts (CheckOutputPath): prints the error and returns
// false when `path` exists and is not a regular file or its directory does not exist.
bool OutputPathUsable(const std::string& path, const std::string& option);

struct RegisterCommand {
  RegisterCommand(std::string name, AddCommand add) {
    CommandRegistry().push_back({std::move(name), std::move(add)});
  }
};

}  // namespace driftlab::cli
