// SIGINT / SIGTERM -> callback on a helper thread, for the remote commands (interrupt.h).
#include "interrupt.h"

#include <semaphore.h>
#include <signal.h>

#include <atomic>
#include <cerrno>
#include <utility>

namespace driftlab::cli {
namespace {

sem_t g_wake;
std::atomic<bool> g_interrupted{false};
std::atomic<bool> g_stopping{false};
struct sigaction g_old_int {};
struct sigaction g_old_term {};

extern "C" void OnInterrupt(int) {
  g_interrupted.store(true);
  sem_post(&g_wake);
}

}  // namespace

InterruptWatch::InterruptWatch(std::function<void()> on_interrupt) {
  sem_init(&g_wake, 0, 0);
  g_interrupted.store(false);
  g_stopping.store(false);
  struct sigaction action {};
  action.sa_handler = OnInterrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &g_old_int);
  sigaction(SIGTERM, &action, &g_old_term);
  helper_ = std::thread([callback = std::move(on_interrupt)] {
    while (true) {
      while (sem_wait(&g_wake) != 0 && errno == EINTR) {
      }
      if (g_stopping.load()) return;
      if (g_interrupted.load()) {
        callback();
        return;
      }
    }
  });
}

InterruptWatch::~InterruptWatch() {
  g_stopping.store(true);
  sem_post(&g_wake);
  helper_.join();
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
  sem_destroy(&g_wake);
}

bool InterruptWatch::interrupted() const { return g_interrupted.load(); }

}  // namespace driftlab::cli
