#include "web/sessions.h"

#include <openssl/crypto.h>
#include <openssl/rand.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "driftlab/server/auth.h"

namespace driftlab::server::web {

std::string RandomHex(size_t bytes) {
  std::vector<unsigned char> random(bytes);
  if (RAND_bytes(random.data(), static_cast<int>(bytes)) != 1) {
    throw std::runtime_error("RAND_bytes failed");
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned char b : random) {
    hex.push_back(kHex[b >> 4]);
    hex.push_back(kHex[b & 15]);
  }
  return hex;
}

bool SecretEquals(const std::string& a, const std::string& b) {
  return a.size() == b.size() && CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

std::string SessionStore::Create(const std::string& owner) {
  const std::string id = RandomHex(32);
  const Clock::time_point now = Clock::now();
  std::lock_guard lock(mutex_);
  while (sessions_.size() >= capacity_ && !sessions_.empty()) {
    const auto oldest = std::min_element(
        sessions_.begin(), sessions_.end(),
        [](const auto& a, const auto& b) { return a.second.last_used < b.second.last_used; });
    sessions_.erase(oldest);
  }
  sessions_[Sha256Hex(id)] = Session{owner, RandomHex(32), now, now};
  return id;
}

std::optional<Session> SessionStore::Find(const std::string& id) {
  if (id.size() != 64) return std::nullopt;
  const std::string key = Sha256Hex(id);
  const Clock::time_point now = Clock::now();
  std::lock_guard lock(mutex_);
  const auto it = sessions_.find(key);
  if (it == sessions_.end()) return std::nullopt;
  if (now - it->second.last_used > idle_ || now - it->second.created > lifetime_) {
    sessions_.erase(it);
    return std::nullopt;
  }
  it->second.last_used = now;
  return it->second;
}

void SessionStore::Remove(const std::string& id) {
  const std::string key = Sha256Hex(id);
  std::lock_guard lock(mutex_);
  sessions_.erase(key);
}

size_t SessionStore::size() const {
  std::lock_guard lock(mutex_);
  return sessions_.size();
}

SignInThrottle::Bucket& SignInThrottle::Refresh(const std::string& client, Clock::time_point now) {
  auto it = buckets_.find(client);
  if (it == buckets_.end()) {
    if (buckets_.size() >= capacity_) {
      // Forget a client whose tries have all come back, else the longest-idle one.
      auto victim = buckets_.begin();
      for (auto b = buckets_.begin(); b != buckets_.end(); ++b) {
        const double refilled =
            b->second.tries + std::chrono::duration<double>(now - b->second.updated) / refill_;
        if (refilled >= burst_) {
          victim = b;
          break;
        }
        if (b->second.updated < victim->second.updated) victim = b;
      }
      buckets_.erase(victim);
    }
    it = buckets_.emplace(client, Bucket{static_cast<double>(burst_), now}).first;
  }
  Bucket& bucket = it->second;
  bucket.tries = std::min<double>(
      burst_, bucket.tries + std::chrono::duration<double>(now - bucket.updated) / refill_);
  bucket.updated = now;
  return bucket;
}

bool SignInThrottle::Allowed(const std::string& client) {
  std::lock_guard lock(mutex_);
  return Refresh(client, Clock::now()).tries >= 1.0;
}

void SignInThrottle::Failed(const std::string& client) {
  std::lock_guard lock(mutex_);
  Bucket& bucket = Refresh(client, Clock::now());
  bucket.tries = std::max(0.0, bucket.tries - 1.0);
}

int SignInThrottle::RetryAfterSeconds(const std::string& client) {
  std::lock_guard lock(mutex_);
  const Bucket& bucket = Refresh(client, Clock::now());
  if (bucket.tries >= 1.0) return 0;
  const double seconds = (1.0 - bucket.tries) * std::chrono::duration<double>(refill_).count();
  return static_cast<int>(seconds) + 1;
}

}  // namespace driftlab::server::web
