#include "driftlab/server/auth.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>

#include <cctype>
#include <fstream>
#include <sstream>

#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

std::array<uint8_t, 32> Sha256(std::string_view text) {
  std::array<uint8_t, 32> digest{};
  unsigned int length = 0;
  EVP_Digest(text.data(), text.size(), digest.data(), &length, EVP_sha256(), nullptr);
  return digest;
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string Sha256Hex(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (uint8_t byte : Sha256(text)) {
    hex.push_back(kHex[byte >> 4]);
    hex.push_back(kHex[byte & 15]);
  }
  return hex;
}

TokenAuthenticator TokenAuthenticator::FromFile(const std::filesystem::path& path) {
  std::ifstream in = OpenInputFile(path, kMaxSmallTextFileBytes, path.string());
  std::vector<Entry> entries;
  std::string line;
  for (int line_number = 1; ReadLine(in, &line, path.string() + ":" + std::to_string(line_number));
       ++line_number) {
    std::istringstream fields(line);
    std::string owner, hash, extra;
    if (!(fields >> owner) || owner[0] == '#') continue;
    const std::string where = path.string() + ":" + std::to_string(line_number);
    if (!(fields >> hash) || (fields >> extra)) {
      throw SpecError(where, "\"" + line + "\"", "OWNER SHA256HEX (two fields)");
    }
    Entry entry;
    entry.owner = owner;
    bool valid = hash.size() == 64;
    for (size_t i = 0; valid && i < 32; ++i) {
      const int high = HexDigit(hash[2 * i]), low = HexDigit(hash[2 * i + 1]);
      valid = high >= 0 && low >= 0;
      entry.sha256[i] = static_cast<uint8_t>(high * 16 + low);
    }
    if (!valid) throw SpecError(where, "\"" + hash + "\"", "64 hex digits (SHA-256 of the token)");
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) throw SpecError(path.string(), "no tokens in the tokens file", 0);
  return TokenAuthenticator(std::move(entries));
}

grpc::Status TokenAuthenticator::Authenticate(const grpc::ServerContext& context,
                                              std::string* owner) const {
  if (!enabled()) {
    *owner = kAnonymousOwner;
    return grpc::Status::OK;
  }
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return AuthenticateHeader("", owner);
  return AuthenticateHeader(std::string_view(it->second.data(), it->second.size()), owner);
}

grpc::Status TokenAuthenticator::AuthenticateHeader(std::string_view authorization,
                                                    std::string* owner) const {
  if (!enabled()) {
    *owner = kAnonymousOwner;
    return grpc::Status::OK;
  }
  if (authorization.empty()) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "missing `authorization: Bearer <token>` metadata");
  }
  constexpr std::string_view kBearer = "Bearer ";
  if (authorization.size() <= kBearer.size() ||
      authorization.substr(0, kBearer.size()) != kBearer) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "authorization metadata is not `Bearer <token>`");
  }
  const std::array<uint8_t, 32> digest = Sha256(authorization.substr(kBearer.size()));
  const Entry* match = nullptr;
  for (const Entry& entry : entries_) {  // every entry compared: no early exit
    if (CRYPTO_memcmp(entry.sha256.data(), digest.data(), digest.size()) == 0) match = &entry;
  }
  if (match == nullptr) return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "unknown token");
  *owner = match->owner;
  return grpc::Status::OK;
}

}  // namespace driftlab::server
