#include "service/auth.hpp"

#include "maps/file_digest.hpp"
#include "maps/json_node.hpp"
#include "maps/text_file.hpp"

#include <algorithm>
#include <cctype>

namespace skylane::service {

namespace {

bool isHexDigest(const std::string& s) {
  return s.size() == 64 && std::all_of(s.begin(), s.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

/// One entry of the tokens file.
std::pair<std::string, Principal> tokenEntry(const maps::JsonNode& e) {
  const std::string digest = e.at("sha256").str();
  if (!isHexDigest(digest)) e.at("sha256").fail("the SHA-256 of the token as 64 lower-case hex digits");
  Principal p;
  p.key = digest;
  if (e.has("role")) {
    if (e.at("role").str() != "authority") e.at("role").fail("\"authority\" (an operator is given by \"operator\")");
    if (e.has("operator")) e.fail("an entry with either \"role\": \"authority\" or \"operator\", not both");
    p.authority = true;
  } else {
    p.operator_id = e.at("operator").str();
    if (p.operator_id.empty() || p.operator_id.size() > 64) e.at("operator").fail("an operator name of 1 to 64 characters");
  }
  return {digest, p};
}

}  // namespace

TokenTable TokenTable::load(const std::string& path) {
  const nlohmann::json doc = maps::readJsonFile(path);
  const maps::JsonNode root{doc, "$", path};
  TokenTable t;
  const maps::JsonNode list = root.at("tokens");
  for (std::size_t i = 0; i < list.array().size(); ++i) {
    auto [digest, p] = tokenEntry(list.item(i));
    if (t.by_digest_.count(digest)) list.item(i).at("sha256").fail("a token listed once");
    t.by_digest_[digest] = std::move(p);
  }
  if (t.by_digest_.empty()) list.fail("at least one token");
  return t;
}

std::optional<Principal> TokenTable::find(const std::string& authorization) const {
  constexpr std::string_view kScheme = "Bearer ";
  if (authorization.size() <= kScheme.size() || authorization.size() > 4096) return std::nullopt;
  if (!std::equal(kScheme.begin(), kScheme.end(), authorization.begin(),
                  [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b)); })) {
    return std::nullopt;
  }
  const auto it = by_digest_.find(maps::sha256Hex(authorization.substr(kScheme.size())));
  if (it == by_digest_.end()) return std::nullopt;
  return it->second;
}

bool RateLimiter::allow(const std::string& key, std::chrono::steady_clock::time_point now, double& retry_after_s) {
  auto [it, fresh] = buckets_.try_emplace(key, Bucket{burst_, now});
  Bucket& b = it->second;
  if (!fresh) {
    b.tokens = std::min(burst_, b.tokens + rate_ * std::chrono::duration<double>(now - b.at).count());
    b.at = now;
  }
  if (b.tokens >= 1.0) {
    b.tokens -= 1.0;
    return true;
  }
  retry_after_s = (1.0 - b.tokens) / rate_;
  return false;
}

}  // namespace skylane::service
