#include "geofence/verdict_json.hpp"

#include "maps/json_numbers.hpp"

namespace skylane::geofence {

using nlohmann::json;

void to_json(json& j, const Check& c) {
  j = json::object();
  j["level"] = levelName(c.level);
  j["verdict"] = verdictName(c.verdict);
  j["subject"] = c.subject;
  j["margin_h_m"] = maps::metresOrNull(c.margin_h_m);
  j["margin_v_m"] = maps::metresOrNull(c.margin_v_m);
  if (isBoxLevel(c)) {
    j["segment"] = c.index;
    j["across_joint"] = c.across_joint;
  } else {
    j["clearance_m"] = c.clearance_m ? maps::metresOrNull(*c.clearance_m) : json(nullptr);
    j["exact"] = c.exact;
  }
}

void to_json(json& j, const FenceVerdict& v) {
  j = json::object();
  j["verdict"] = verdictName(v.verdict);
  j["violated"] = v.violated ? json(levelName(*v.violated)) : json(nullptr);
  j["checks"] = v.checks;
}

json pickMembers(const json& object, std::initializer_list<const char*> keys) {
  json out = json::object();
  for (const char* k : keys) {
    const auto it = object.find(k);
    if (it != object.end()) out[k] = *it;
  }
  return out;
}

}  // namespace skylane::geofence
