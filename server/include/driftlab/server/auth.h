// Bearer-token authentication of driftlab-server from a file of hashed tokens.
//
// Tokens file: one `OWNER SHA256HEX` per line (the SHA-256 of the token, 64 lowercase or uppercase
// hex digits, as `driftlab-server hash-token TOKEN` prints it); blank lines and lines starting with
// '#' are ignored. The server never stores a token, only its hash. A call carries
// `authorization: Bearer <token>`; the token is hashed and compared with every stored hash in
// constant time (CRYPTO_memcmp over all entries, no early exit), so timing tells nothing about
// which stored hash is close. Without a tokens file every call is owner "anonymous".
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/server/service_common.h"

namespace driftlab::server {

inline constexpr const char* kAnonymousOwner = "anonymous";

// Lowercase hex SHA-256 of `text` (FIPS 180-4, OpenSSL).
std::string Sha256Hex(std::string_view text);

class TokenAuthenticator : public Authenticator {
 public:
  struct Entry {
    std::string owner;
    std::array<uint8_t, 32> sha256{};
  };

  // No tokens: every call is owner "anonymous".
  TokenAuthenticator() = default;
  explicit TokenAuthenticator(std::vector<Entry> entries) : entries_(std::move(entries)) {}

  // Reads a tokens file. Throws SpecError naming "<file>:<line>" for a malformed line and the file
  // for an unreadable or empty one.
  static TokenAuthenticator FromFile(const std::filesystem::path& path);

  grpc::Status Authenticate(const grpc::ServerContext& context, std::string* owner) const override;
  // The same check on the raw metadata value ("Bearer <token>"; empty = absent).
  grpc::Status AuthenticateHeader(std::string_view authorization, std::string* owner) const;

  bool enabled() const { return !entries_.empty(); }
  size_t size() const { return entries_.size(); }

 private:
  std::vector<Entry> entries_;
};

}  // namespace driftlab::server
