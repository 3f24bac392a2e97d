// Running the `driftlab` binary as a child process from tests: a scratch directory per test and
// RunDriftlab(args) capturing exit status, stdout and stderr. Header-only; used by every
// tests/cli/*cli_test.cc (DRIFTLAB_CLI, the binary's path, comes from test_paths.h).
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace driftlab::testing {

namespace fs = std::filesystem;

struct Result {
  int exit_status = -1;
  std::string out;
  std::string err;
};

inline std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A fresh scratch directory per test, removed at the end.
class Scratch {
 public:
  Scratch() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    dir_ =
        fs::temp_directory_path() / ("driftlab_cli_test_" + std::to_string(getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~Scratch() { fs::remove_all(dir_); }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
};

// Runs the program argv_strings[0] (a path) with its arguments; stdout and stderr go to files in
// `scratch`.
inline Result RunProgram(std::vector<std::string> argv_strings, const Scratch& scratch) {
  const fs::path out_file = scratch.dir() / "stdout.txt";
  const fs::path err_file = scratch.dir() / "stderr.txt";
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  Result result;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) == 0) {
    int status = 0;
    waitpid(pid, &status, 0);
    result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  posix_spawn_file_actions_destroy(&actions);
  result.out = ReadFile(out_file);
  result.err = ReadFile(err_file);
  return result;
}

// Runs the driftlab binary with `args`.
inline Result RunDriftlab(const std::vector<std::string>& args, const Scratch& scratch) {
  std::vector<std::string> argv_strings = {DRIFTLAB_CLI};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  return RunProgram(argv_strings, scratch);
}

}  // namespace driftlab::testing
