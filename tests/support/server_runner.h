// Running driftlab-server as a child process from tests: on 127.0.0.1 with an ephemeral port,
// its data in a directory the test chooses, its stdout/stderr in files next to it.
//
//   driftlab::testing::Scratch scratch;                       // cli_runner.h: temp dir per test
//   driftlab::testing::ServerProcess server(scratch.dir() / "data", {"--max-queued-jobs", "4"});
//   ASSERT_TRUE(server.running()) << server.Log();
//   auto channel = grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials());
//   ...
//   server.Kill(SIGKILL); server.Wait();                      // or let the destructor do it
//
// The server is started with `--listen 127.0.0.1:0 --port-file F`; the constructor polls F (the
// server writes it atomically once its port is bound) every 5 ms up to a deadline, and gives up
// early when the child exits. No sleep is used as synchronisation. Header-only; the including
// test gets DRIFTLAB_SERVER_BINARY (the server's path) and DRIFTLAB_CLI from test_paths.h
// (force-included into every test source).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.h"

namespace driftlab::testing {

class ServerProcess {
 public:
  // Starts the server on `data_dir` (created if needed) with `extra_args` appended (e.g.
  // {"--tokens", path}); logs go to data_dir/../server-<n>.{out,err}.
  explicit ServerProcess(const fs::path& data_dir, const std::vector<std::string>& extra_args = {},
                         std::chrono::milliseconds start_timeout = std::chrono::seconds(30),
                         const std::string& binary = DRIFTLAB_SERVER_BINARY) {
    fs::create_directories(data_dir);
    static int counter = 0;
    const std::string stem = "server-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
    const fs::path base = data_dir.parent_path().empty() ? data_dir : data_dir.parent_path();
    port_file_ = base / (stem + ".port");
    out_file_ = base / (stem + ".out");
    err_file_ = base / (stem + ".err");
    fs::remove(port_file_);
    std::vector<std::string> args = {
        binary,        "--listen",         "127.0.0.1:0", "--data", data_dir.string(),
        "--port-file", port_file_.string()};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    std::vector<char*> argv;
    for (std::string& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_file_.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_file_.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int rc = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
      pid_ = -1;
      return;
    }
    const auto deadline = std::chrono::steady_clock::now() + start_timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (fs::exists(port_file_)) {
        port_ = std::stoi(ReadFile(port_file_));
        return;
      }
      if (Exited()) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // polling interval
    }
  }

  ~ServerProcess() {
    if (pid_ > 0 && exit_status_ < 0) {
      Kill(SIGKILL);
      Wait();
    }
  }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  // True when the server bound its port and has not exited.
  bool running() { return port_ > 0 && !Exited(); }
  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }

  void Kill(int signal_number) {
    if (pid_ > 0 && exit_status_ < 0) kill(pid_, signal_number);
  }
  // Waits for the exit: exit code, or 128 + signal number; -1 if still running at the timeout.
  int Wait(std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!Exited()) {
      if (std::chrono::steady_clock::now() >= deadline) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // polling interval
    }
    return exit_status_;
  }

  std::string Log() const { return ReadFile(err_file_); }
  std::string Stdout() const { return ReadFile(out_file_); }

 private:
  bool Exited() {
    if (pid_ <= 0) return true;
    if (exit_status_ >= 0) return true;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return true;
    }
    return false;
  }

  pid_t pid_ = -1;
  int port_ = 0;
  int exit_status_ = -1;
  fs::path port_file_, out_file_, err_file_;
};

}  // namespace driftlab::testing
