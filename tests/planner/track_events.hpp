#pragma once
// Selecting events of a `skylane track` output, for the tracking tests.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace skylane::test {

/// The events of one type, in order.
inline std::vector<nlohmann::json> ofType(const std::vector<nlohmann::json>& events, const std::string& type) {
  std::vector<nlohmann::json> out;
  for (const nlohmann::json& e : events) {
    if (e.at("event") == type) out.push_back(e);
  }
  return out;
}

}  // namespace skylane::test
