// Ctrl-C during a remote call: while an InterruptWatch lives, SIGINT and SIGTERM do not end the
// process but run a callback on a helper thread (e.g. grpc::ClientContext::TryCancel of a Watch
// stream), so the command can cancel the remote job and exit cleanly. The signal handler itself
// only posts a semaphore (sem_post is async-signal-safe, POSIX.1-2008 signal-safety(7)).
#pragma once

#include <functional>
#include <thread>

namespace driftlab::cli {

class InterruptWatch {
 public:
  // Installs the handlers (saving the previous ones) and starts the helper thread, which calls
  // `on_interrupt` once when the first SIGINT or SIGTERM arrives. One instance at a time.
  explicit InterruptWatch(std::function<void()> on_interrupt);
  // Stops the helper thread and restores the previous handlers.
  ~InterruptWatch();
  InterruptWatch(const InterruptWatch&) = delete;
  InterruptWatch& operator=(const InterruptWatch&) = delete;

  // True once a signal arrived.
  bool interrupted() const;

 private:
  std::thread helper_;
};

}  // namespace driftlab::cli
