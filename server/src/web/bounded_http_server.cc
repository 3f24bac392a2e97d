#include "web/bounded_http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <openssl/err.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <thread>
#include <vector>

#include "driftlab/spec_error.h"

namespace driftlab::server::web {
namespace {

using Clock = std::chrono::steady_clock;

// Set on the accept thread while it closes a connection that found the queue full.
thread_local bool t_reject_busy = false;

constexpr char kBusyResponse[] =
    "HTTP/1.1 503 Service Unavailable\r\nRetry-After: 1\r\nContent-Type: text/plain\r\n"
    "Content-Length: 30\r\nConnection: close\r\n\r\nthe web server is busy; retry\n";

std::string OpenSslError() {
  const unsigned long code = ERR_get_error();
  if (code == 0) return "unknown OpenSSL error";
  char text[256];
  ERR_error_string_n(code, text, sizeof(text));
  ERR_clear_error();
  return text;
}

std::string AddressText(const sockaddr_storage& address, int* port) {
  char text[INET6_ADDRSTRLEN] = "";
  *port = 0;
  if (address.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<const sockaddr_in*>(&address);
    inet_ntop(AF_INET, &in->sin_addr, text, sizeof(text));
    *port = ntohs(in->sin_port);
  } else if (address.ss_family == AF_INET6) {
    const auto* in6 = reinterpret_cast<const sockaddr_in6*>(&address);
    inet_ntop(AF_INET6, &in6->sin6_addr, text, sizeof(text));
    *port = ntohs(in6->sin6_port);
  }
  return text;
}

// Milliseconds until `deadline`, at least 0, for poll(2).
int MillisecondsUntil(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return static_cast<int>(std::clamp<int64_t>(left.count(), 0, 60'000));
}

// One connection as an httplib::Stream: non-blocking reads and writes (plain or TLS) with a
// per-request byte budget and deadlines.
class BoundedStream final : public httplib::Stream {
 public:
  BoundedStream(int fd, int stop_fd, SSL* ssl, ConnectionCounters* counters)
      : fd_(fd), stop_fd_(stop_fd), ssl_(ssl), counters_(counters) {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    if (getpeername(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
      remote_ip_ = AddressText(address, &remote_port_);
    }
    length = sizeof(address);
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
      local_ip_ = AddressText(address, &local_port_);
    }
  }

  // A new request: its bytes count from here and must all arrive before `read_deadline`.
  void BeginRequest(Clock::time_point read_deadline, size_t max_bytes,
                    std::chrono::milliseconds write_timeout) {
    read_deadline_ = read_deadline;
    budget_ = max_bytes;
    write_timeout_ = write_timeout;
    writing_ = false;
  }

  // TLS handshake before `deadline`.
  bool Handshake(Clock::time_point deadline) {
    for (;;) {
      const int rc = SSL_accept(ssl_);
      if (rc == 1) return true;
      const int error = SSL_get_error(ssl_, rc);
      if (error == SSL_ERROR_WANT_READ) {
        if (!Wait(POLLIN, deadline)) return false;
      } else if (error == SSL_ERROR_WANT_WRITE) {
        if (!Wait(POLLOUT, deadline)) return false;
      } else {
        ERR_clear_error();
        return false;
      }
    }
  }

  // Waits up to `timeout` for the next request's first byte; false when none comes, Stop() was
  // called or `give_up()` becomes true (checked every 50 ms).
  bool WaitForNextRequest(std::chrono::milliseconds timeout, const std::function<bool()>& give_up) {
    if (Buffered()) return true;
    const Clock::time_point deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
      if (give_up()) return false;
      const Clock::time_point step =
          std::min(deadline, Clock::now() + std::chrono::milliseconds(50));
      if (Wait(POLLIN, step, /*count_timeout=*/false)) return true;
      if (stopped_) return false;
    }
    return false;
  }

  bool is_readable() const override { return Buffered() || !stopped_; }
  bool is_writable() const override { return !stopped_ && !failed_; }

  ssize_t read(char* ptr, size_t size) override {
    if (size == 0) return 0;
    if (begin_ == end_ && !Fill()) return -1;
    size = std::min({size, end_ - begin_, budget_});
    if (size == 0) {
      // The request is over its byte budget.
      counters_->too_large.fetch_add(1);
      failed_ = true;
      return -1;
    }
    std::memcpy(ptr, buffer_.data() + begin_, size);
    begin_ += size;
    budget_ -= size;
    return static_cast<ssize_t>(size);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (failed_) return -1;
    if (!writing_) {
      writing_ = true;
      write_deadline_ = Clock::now() + write_timeout_;
    }
    size_t done = 0;
    while (done < size) {
      ssize_t n = 0;
      short want = POLLOUT;
      if (ssl_ != nullptr) {
        size_t written = 0;
        const int rc = SSL_write_ex(ssl_, ptr + done, size - done, &written);
        if (rc == 1) {
          n = static_cast<ssize_t>(written);
        } else {
          const int error = SSL_get_error(ssl_, rc);
          if (error != SSL_ERROR_WANT_READ && error != SSL_ERROR_WANT_WRITE) return Fail();
          want = error == SSL_ERROR_WANT_READ ? POLLIN : POLLOUT;
          n = -1;
        }
      } else {
        n = ::send(fd_, ptr + done, size - done, MSG_NOSIGNAL);
        if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return Fail();
      }
      if (n > 0) {
        done += static_cast<size_t>(n);
      } else if (!Wait(want, write_deadline_)) {
        return Fail();
      }
    }
    return static_cast<ssize_t>(size);
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = remote_ip_;
    port = remote_port_;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = local_ip_;
    port = local_port_;
  }
  socket_t socket() const override { return fd_; }

  const std::string& remote_ip() const { return remote_ip_; }
  bool failed() const { return failed_; }

 private:
  bool Buffered() const { return begin_ < end_ || (ssl_ != nullptr && SSL_pending(ssl_) > 0); }

  ssize_t Fail() {
    failed_ = true;
    return -1;
  }

  // Reads what is available (waiting until the read deadline) into the buffer.
  bool Fill() {
    begin_ = end_ = 0;
    for (;;) {
      short want = POLLIN;
      if (ssl_ != nullptr) {
        size_t got = 0;
        const int rc = SSL_read_ex(ssl_, buffer_.data(), buffer_.size(), &got);
        if (rc == 1) {
          end_ = got;
          return true;
        }
        const int error = SSL_get_error(ssl_, rc);
        if (error == SSL_ERROR_ZERO_RETURN) return false;
        if (error != SSL_ERROR_WANT_READ && error != SSL_ERROR_WANT_WRITE) {
          ERR_clear_error();
          return false;
        }
        want = error == SSL_ERROR_WANT_READ ? POLLIN : POLLOUT;
      } else {
        const ssize_t n = ::recv(fd_, buffer_.data(), buffer_.size(), 0);
        if (n > 0) {
          end_ = static_cast<size_t>(n);
          return true;
        }
        if (n == 0) return false;
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return false;
      }
      if (!Wait(want, read_deadline_)) {
        failed_ = true;
        return false;
      }
    }
  }

  // Waits for `events` on the socket until `deadline`; false on timeout (counted in
  // ConnectionCounters::timed_out when `count_timeout`), Stop() or error.
  bool Wait(short events, Clock::time_point deadline, bool count_timeout = true) {
    for (;;) {
      pollfd fds[2] = {{fd_, events, 0}, {stop_fd_, POLLIN, 0}};
      const int rc = ::poll(fds, 2, MillisecondsUntil(deadline));
      if (rc < 0 && errno == EINTR) continue;
      if (rc < 0) return false;
      if (fds[1].revents != 0) {
        stopped_ = true;
        return false;
      }
      if (rc == 0) {
        if (Clock::now() < deadline) continue;
        if (count_timeout) counters_->timed_out.fetch_add(1);
        return false;
      }
      return (fds[0].revents & (events | POLLHUP | POLLERR)) != 0;
    }
  }

  int fd_;
  int stop_fd_;
  SSL* ssl_;
  ConnectionCounters* counters_;
  std::string remote_ip_, local_ip_;
  int remote_port_ = 0, local_port_ = 0;
  std::array<char, 16 << 10> buffer_{};
  size_t begin_ = 0, end_ = 0;
  size_t budget_ = 0;
  Clock::time_point read_deadline_ = Clock::now();
  Clock::time_point write_deadline_ = Clock::now();
  std::chrono::milliseconds write_timeout_{0};
  bool writing_ = false;
  bool failed_ = false;
  bool stopped_ = false;
};

}  // namespace

// The worker threads and the bounded queue of accepted connections.
class BoundedHttpServer::Pool final : public httplib::TaskQueue {
 public:
  Pool(BoundedHttpServer* server, int threads, size_t capacity)
      : server_(server), capacity_(capacity) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Work(); });
  }
  ~Pool() override {
    shutdown();
    std::lock_guard lock(server_->mutex_);
    if (server_->pool_ == this) server_->pool_ = nullptr;
  }

  void enqueue(std::function<void()> fn) override {
    {
      std::lock_guard lock(mutex_);
      if (!stopped_ && jobs_.size() < capacity_) {
        jobs_.push_back(std::move(fn));
        changed_.notify_one();
        return;
      }
    }
    // Queue full: the connection is answered 503 and closed here, on the accept thread.
    server_->counters_.busy.fetch_add(1);
    t_reject_busy = true;
    fn();
    t_reject_busy = false;
  }

  void shutdown() override {
    {
      std::lock_guard lock(mutex_);
      if (stopped_ && threads_.empty()) return;
      stopped_ = true;
      changed_.notify_all();
    }
    for (std::thread& t : threads_) t.join();
    threads_.clear();
  }

  size_t waiting() {
    std::lock_guard lock(mutex_);
    return jobs_.size();
  }

 private:
  void Work() {
    for (;;) {
      std::function<void()> fn;
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [this] { return stopped_ || !jobs_.empty(); });
        if (jobs_.empty()) return;  // stopped and drained
        fn = std::move(jobs_.front());
        jobs_.pop_front();
      }
      fn();
    }
  }

  BoundedHttpServer* server_;
  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  bool stopped_ = false;
};

TlsContext::TlsContext(const std::filesystem::path& cert, const std::filesystem::path& key) {
  ctx_ = SSL_CTX_new(TLS_server_method());
  if (ctx_ == nullptr) throw SpecError("--tls-cert", cert.string(), "a usable TLS certificate");
  SSL_CTX_set_min_proto_version(ctx_, TLS1_2_VERSION);
  SSL_CTX_set_mode(ctx_, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER);
  SSL_CTX_set_options(ctx_, SSL_OP_NO_RENEGOTIATION);
  if (SSL_CTX_use_certificate_chain_file(ctx_, cert.c_str()) != 1) {
    const std::string error = OpenSslError();
    SSL_CTX_free(ctx_);
    throw SpecError("--tls-cert", cert.string(), "a PEM certificate chain (" + error + ")");
  }
  if (SSL_CTX_use_PrivateKey_file(ctx_, key.c_str(), SSL_FILETYPE_PEM) != 1 ||
      SSL_CTX_check_private_key(ctx_) != 1) {
    const std::string error = OpenSslError();
    SSL_CTX_free(ctx_);
    throw SpecError("--tls-key", key.string(), "the PEM private key of --tls-cert (" + error + ")");
  }
}

TlsContext::~TlsContext() { SSL_CTX_free(ctx_); }

BoundedHttpServer::BoundedHttpServer(const ConnectionLimits& limits, const TlsContext* tls,
                                     std::function<void(httplib::Request&)> setup)
    : limits_(limits), tls_(tls), setup_(std::move(setup)) {
  stop_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (stop_fd_ < 0) throw std::runtime_error("eventfd failed");
  new_task_queue = [this] {
    auto* pool = new Pool(this, limits_.threads, limits_.queue);
    std::lock_guard lock(mutex_);
    pool_ = pool;
    return pool;
  };
}

BoundedHttpServer::~BoundedHttpServer() {
  if (stop_fd_ >= 0) close(stop_fd_);
}

void BoundedHttpServer::Stop() {
  stopping_ = true;
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(stop_fd_, &one, sizeof(one));
  stop();
}

size_t BoundedHttpServer::waiting() const {
  std::lock_guard lock(mutex_);
  return pool_ != nullptr ? pool_->waiting() : 0;
}

bool BoundedHttpServer::Enter(const std::string& address) {
  std::lock_guard lock(mutex_);
  int& count = per_client_[address];
  if (count >= limits_.per_client) {
    if (count == 0) per_client_.erase(address);
    return false;
  }
  ++count;
  return true;
}

void BoundedHttpServer::Leave(const std::string& address) {
  std::lock_guard lock(mutex_);
  const auto it = per_client_.find(address);
  if (it != per_client_.end() && --it->second <= 0) per_client_.erase(it);
}

bool BoundedHttpServer::WidenBacklog() {
  const socket_t sock = svr_sock_;
  return sock != INVALID_SOCKET && ::listen(sock, SOMAXCONN) == 0;
}

bool BoundedHttpServer::process_and_close_socket(socket_t sock) {
  counters_.accepted.fetch_add(1);
  const int flags = fcntl(sock, F_GETFL, 0);
  fcntl(sock, F_SETFL, flags | O_NONBLOCK);
  const auto close_socket = [sock] {
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
  };
  if (t_reject_busy || stopping_) {
    if (tls_ == nullptr) {
      [[maybe_unused]] const ssize_t n =
          ::send(sock, kBusyResponse, sizeof(kBusyResponse) - 1, MSG_NOSIGNAL);
    }
    close_socket();
    return false;
  }

  SSL* ssl = nullptr;
  if (tls_ != nullptr) {
    ssl = SSL_new(tls_->get());
    if (ssl == nullptr || SSL_set_fd(ssl, sock) != 1) {
      if (ssl != nullptr) SSL_free(ssl);
      close_socket();
      return false;
    }
  }
  bool ok = false;
  {
    BoundedStream stream(sock, stop_fd_, ssl, &counters_);
    const std::string client = stream.remote_ip();
    if (!Enter(client)) {
      counters_.per_client.fetch_add(1);
      if (ssl == nullptr) {
        [[maybe_unused]] const ssize_t n =
            ::send(sock, kBusyResponse, sizeof(kBusyResponse) - 1, MSG_NOSIGNAL);
      }
    } else {
      const bool handshake =
          ssl == nullptr || stream.Handshake(Clock::now() + limits_.request_timeout);
      if (!handshake) counters_.tls_failed.fetch_add(1);
      for (size_t n = 0; handshake && n < limits_.max_requests_per_connection; ++n) {
        if (n > 0 && !stream.WaitForNextRequest(limits_.keep_alive_timeout, [this] {
              return stopping_.load() || waiting() > 0;
            })) {
          break;
        }
        stream.BeginRequest(Clock::now() + limits_.request_timeout, limits_.max_request_bytes,
                            limits_.write_timeout);
        const bool last = n + 1 == limits_.max_requests_per_connection || stopping_;
        bool closed = false;
        ok = process_request(stream, last, closed, setup_);
        if (!ok || closed || last || stream.failed()) break;
      }
      Leave(client);
    }
    if (ssl != nullptr) {
      if (ok && !stream.failed()) SSL_shutdown(ssl);  // one non-blocking close_notify
      SSL_free(ssl);
      ERR_clear_error();
    }
  }
  close_socket();
  return ok;
}

}  // namespace driftlab::server::web
