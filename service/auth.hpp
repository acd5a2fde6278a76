#pragma once
/// \file
/// \brief Who is asking: bearer tokens, kept only as their SHA-256 digests, each mapped to an
/// operator or to the authority role; and a rate limit per token (a token bucket).
///
/// The tokens file (JSON): {"tokens": [{"sha256": "<64 hex>", "operator": "acme"},
/// {"sha256": "<64 hex>", "role": "authority"}]}. A token is looked up by its digest, so the
/// service never holds a token in clear and the lookup time does not depend on how much of a
/// guessed token is right.

#include <chrono>
#include <cstddef>
#include <map>
#include <optional>
#include <algorithm>
#include <string>
#include <vector>
#include <unordered_map>

namespace skylane::service {

/// \brief An authenticated caller.
struct Principal {
  std::string key;        ///< the token's digest (rate limits and logs name the caller by it)
  std::string operator_id;  ///< empty for the authority
  bool authority = false;
  /// \brief The owner recorded on what this caller creates ("" for the authority).
  [[nodiscard]] const std::string& owner() const { return operator_id; }
};

/// \brief The known tokens.
class TokenTable {
 public:
  /// \brief Reads the tokens file.
  /// \throws maps::ParseError naming the file, the entry and the field.
  static TokenTable load(const std::string& path);
  /// \brief The caller of an `Authorization` header value ("Bearer <token>"), if known.
  [[nodiscard]] std::optional<Principal> find(const std::string& authorization) const;
  [[nodiscard]] std::size_t size() const { return by_digest_.size(); }
  /// \brief The operators the tokens stand for (each once).
  [[nodiscard]] std::vector<std::string> operators() const {
    std::vector<std::string> out;
    for (const auto& [digest, p] : by_digest_) {
      if (!p.authority && std::find(out.begin(), out.end(), p.operator_id) == out.end()) out.push_back(p.operator_id);
    }
    return out;
  }
  /// \brief Adds one (tests).
  void add(const std::string& sha256_hex, Principal p) { by_digest_[sha256_hex] = std::move(p); }

 private:
  std::unordered_map<std::string, Principal> by_digest_;
};

/// \brief A token bucket per caller: `rate` requests per second, bursts of `burst`.
class RateLimiter {
 public:
  RateLimiter(double rate_per_s, double burst) : rate_(rate_per_s), burst_(burst) {}
  /// \brief Takes one request's token; false when the caller is over its rate, with the seconds
  /// until a token is back in `retry_after_s`.
  bool allow(const std::string& key, std::chrono::steady_clock::time_point now, double& retry_after_s);

 private:
  struct Bucket {
    double tokens;
    std::chrono::steady_clock::time_point at;
  };
  double rate_, burst_;
  std::unordered_map<std::string, Bucket> buckets_;
};

}  // namespace skylane::service
