// The connection layer of driftlab-server's web pages: cpp-httplib's request parsing, routing and
// response writing (Debian's libcpp-httplib 0.11), under connection handling of our own that keeps
// every client's cost bounded. httplib's own connection loop reads a request head of any number
// of header lines, gives a client that sends one byte every few seconds unlimited time, and queues
// accepted connections without limit; here:
//
//  * a fixed pool of worker threads and a bounded queue of accepted connections: a connection
//    that finds the queue full is closed at once (with "503 Service Unavailable" over plain HTTP);
//  * at most `per_client` connections of one remote address in the workers: more get 503 too;
//  * each request (request line, headers and body) must arrive within `request_timeout` and in at
//    most `max_request_bytes`, or the connection is closed; each response must be written within
//    `write_timeout`; an idle keep-alive connection is closed after `keep_alive_timeout`, and at
//    once when connections are waiting for a worker;
//  * TLS (OpenSSL) with the server's certificate, its handshake under the same request deadline;
//  * Stop() wakes every waiting connection (an eventfd in every poll).
//
// Every socket operation is non-blocking with poll(2) and a deadline, so no client can hold a
// worker longer than request_timeout + write_timeout per request. SIGPIPE must be ignored by the
// process (driftlab-server's main does; OpenSSL writes with write(2)).
#pragma once

#include <httplib.h>
#include <openssl/ssl.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace driftlab::server::web {

struct ConnectionLimits {
  int threads = 32;    // worker threads
  size_t queue = 128;  // accepted connections waiting for a worker
  int per_client = 8;  // connections of one remote address in the workers
  std::chrono::milliseconds request_timeout{10000};  // request line + headers + body
  std::chrono::milliseconds write_timeout{60000};    // one response
  std::chrono::milliseconds keep_alive_timeout{5000};
  size_t max_request_bytes = 64 << 10;  // request line + headers + body
  size_t max_requests_per_connection = 100;
};

// Counts of what the connection layer refused, for the log and the tests.
struct ConnectionCounters {
  std::atomic<uint64_t> accepted{0};
  std::atomic<uint64_t> busy{0};        // queue full
  std::atomic<uint64_t> per_client{0};  // over the per-client limit
  std::atomic<uint64_t> timed_out{0};   // request or response past its deadline
  std::atomic<uint64_t> too_large{0};   // request over max_request_bytes
  std::atomic<uint64_t> tls_failed{0};  // TLS handshake failed
};

// A server-side TLS context from PEM files (certificate chain and private key), TLS 1.2 or newer.
// Throws SpecError naming the option when a file cannot be used.
class TlsContext {
 public:
  TlsContext(const std::filesystem::path& cert, const std::filesystem::path& key);
  ~TlsContext();
  TlsContext(const TlsContext&) = delete;
  TlsContext& operator=(const TlsContext&) = delete;
  SSL_CTX* get() const { return ctx_; }

 private:
  SSL_CTX* ctx_ = nullptr;
};

class BoundedHttpServer : public httplib::Server {
 public:
  // `tls` (may be null: plain HTTP) outlives the server. `setup` is called with every request
  // after its head is read and before routing (the request is still mutable there).
  BoundedHttpServer(const ConnectionLimits& limits, const TlsContext* tls,
                    std::function<void(httplib::Request&)> setup);
  ~BoundedHttpServer() override;

  // After bind_to_port / bind_to_any_port: widens the listening socket's backlog from the 5 that
  // libcpp-httplib 0.11 is built with to SOMAXCONN (listen(2) on a listening socket sets its
  // backlog anew). With 5, a burst of connections overflows the kernel's accept queue and each
  // connection past it waits for SYN-ACK retransmissions (1 s, 3 s, 7 s, ...) before this server
  // sees it; the accept thread drains the queue at once and refuses what the workers' queue
  // cannot hold (503), so a wide backlog costs no worker. Returns false when listen(2) fails.
  bool WidenBacklog();

  // Stops accepting, wakes every waiting connection; listen_after_bind() then returns once the
  // workers have finished their current request.
  void Stop();

  const ConnectionCounters& counters() const { return counters_; }
  // Connections waiting for a worker.
  size_t waiting() const;

 private:
  class Pool;
  bool process_and_close_socket(socket_t sock) override;
  // Connections of `address` in the workers: +1 (false when over the limit) and -1.
  bool Enter(const std::string& address);
  void Leave(const std::string& address);

  ConnectionLimits limits_;
  const TlsContext* tls_;
  std::function<void(httplib::Request&)> setup_;
  int stop_fd_ = -1;  // eventfd, readable after Stop()
  std::atomic<bool> stopping_{false};
  Pool* pool_ = nullptr;  // owned by httplib (new_task_queue), valid while listening
  mutable std::mutex mutex_;
  std::map<std::string, int> per_client_;
  ConnectionCounters counters_;
};

}  // namespace driftlab::server::web
