// Sign-in state of the web pages: sessions (a random cookie value -> the owner of the token that
// signed in, with a CSRF token) and the per-client limit on failed sign-ins.
//
// A session id is 32 random bytes (OpenSSL RAND_bytes) as hex, sent only in the session cookie;
// the store keeps its SHA-256, so a lookup compares hashes and a memory dump holds no usable
// cookie. Sessions live in memory: a server restart signs everyone out. A session ends after
// `idle` without a request or `lifetime` after sign-in, and the store holds at most `capacity`
// (the least recently used goes first).
//
// SignInThrottle: each client (remote address) has `burst` tries; one try comes back every
// `refill`. A failed sign-in takes a try; with none left every sign-in of that client is refused,
// the right token included, so guessing stays at burst + t / refill tries in time t. A successful
// sign-in does not refill. At most `capacity` clients are tracked; when full, clients whose tries
// have all come back are forgotten first, then the longest-idle.
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <mutex>
#include <optional>
#include <string>

namespace driftlab::server::web {

using Clock = std::chrono::steady_clock;

struct Session {
  std::string owner;
  std::string csrf;  // per-session token the forms carry (hex, 32 random bytes)
  Clock::time_point created;
  Clock::time_point last_used;
};

// Lowercase hex of `bytes` random bytes (OpenSSL RAND_bytes); throws std::runtime_error on failure.
std::string RandomHex(size_t bytes);

// Constant-time comparison of two strings of any length (CRYPTO_memcmp over equal lengths).
bool SecretEquals(const std::string& a, const std::string& b);

class SessionStore {
 public:
  SessionStore(std::chrono::seconds idle, std::chrono::seconds lifetime, size_t capacity)
      : idle_(idle), lifetime_(lifetime), capacity_(capacity) {}

  // A new session of `owner`; returns its id (the cookie value).
  std::string Create(const std::string& owner);
  // The live session with this id (its last use set to now), or none.
  std::optional<Session> Find(const std::string& id);
  void Remove(const std::string& id);
  size_t size() const;

 private:
  std::chrono::seconds idle_, lifetime_;
  size_t capacity_;
  mutable std::mutex mutex_;
  std::map<std::string, Session> sessions_;  // by SHA-256 hex of the id
};

class SignInThrottle {
 public:
  SignInThrottle(int burst, std::chrono::seconds refill, size_t capacity)
      : burst_(burst), refill_(refill), capacity_(capacity) {}

  // True when `client` may try to sign in now.
  bool Allowed(const std::string& client);
  // Records a failed try of `client`.
  void Failed(const std::string& client);
  // Seconds until `client` has a try again (0 = now).
  int RetryAfterSeconds(const std::string& client);

 private:
  struct Bucket {
    double tries = 0;  // tries left, refilled continuously up to burst
    Clock::time_point updated;
  };
  Bucket& Refresh(const std::string& client, Clock::time_point now);

  int burst_;
  std::chrono::seconds refill_;
  size_t capacity_;
  std::mutex mutex_;
  std::map<std::string, Bucket> buckets_;
};

}  // namespace driftlab::server::web
