#include "planner/tracking/flight_state.hpp"

#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace skylane::planner {

using nlohmann::json;

json flightStateJson(const FlightState& s) {
  json j;
  j["last_time"] = s.last_time ? json(maps::formatRfc3339(*s.last_time, 3)) : json(nullptr);
  j["level1_window"] = s.level1_window;
  j["level2_window"] = s.level2_window;
  j["violated"] = s.violated;
  j["inside_streak"] = s.inside_streak;
  j["last_replan"] = s.last_replan ? json(maps::formatRfc3339(*s.last_replan, 3)) : json(nullptr);
  j["stale_reported"] = s.stale_reported;
  j["arrived"] = s.arrived;
  j["next_stop"] = s.next_stop;
  j["route_version"] = s.route_version;
  j["fixes"] = s.fixes;
  j["reruns"] = s.rerun_count;
  j["replans"] = s.replans;
  j["clock_offset_s"] = s.clock_offset_s;
  j["handoff_since"] = s.handoff_since ? json(maps::formatRfc3339(*s.handoff_since, 3)) : json(nullptr);
  j["handoff_awaits_link"] = s.handoff_awaits_link;
  j["handoff_inside"] = s.handoff_inside;
  return j;
}

namespace {

/// A per-level array; one of 4 (stored before the keep-in level) leaves the keep-in entry at 0.
template <typename T, std::size_t N>
void perLevel(const maps::JsonNode& n, std::array<T, N>& out) {
  const std::vector<T> v = n.j.get<std::vector<T>>();
  if (v.size() != N && v.size() != N - 1) n.fail("an array of " + std::to_string(N) + " (one per level)");
  out = {};
  std::copy(v.begin(), v.end(), out.begin());
}

}  // namespace

FlightState parseFlightState(const json& j, const std::string& source) {
  const maps::JsonNode root{j, "$", source};
  FlightState s;
  try {
    auto time = [&](const char* key) -> std::optional<maps::GpsTime> {
      if (!root.has(key)) return std::nullopt;
      const auto t = maps::parseRfc3339(root.at(key).str());
      if (!t) root.at(key).fail("an RFC 3339 date-time");
      return t;
    };
    s.last_time = time("last_time");
    s.last_replan = time("last_replan");
    s.level1_window = j.at("level1_window").get<std::vector<bool>>();
    s.level2_window = j.at("level2_window").get<std::vector<bool>>();
    perLevel(root.at("violated"), s.violated);
    perLevel(root.at("inside_streak"), s.inside_streak);
    s.stale_reported = j.at("stale_reported").get<bool>();
    s.arrived = j.value("arrived", false);
    s.next_stop = j.at("next_stop").get<std::size_t>();
    s.route_version = j.at("route_version").get<int>();
    s.fixes = j.at("fixes").get<std::uint64_t>();
    s.rerun_count = j.at("reruns").get<std::uint64_t>();
    s.replans = j.at("replans").get<std::uint64_t>();
    s.clock_offset_s = j.value("clock_offset_s", 0.0);
    s.handoff_since = time("handoff_since");
    s.handoff_awaits_link = j.value("handoff_awaits_link", false);
    s.handoff_inside = j.value("handoff_inside", 0);
  } catch (const nlohmann::json::exception& e) {
    throw maps::ParseError(source, 0, "$", maps::quoteJson(j), std::string("a tracker flight state (") + e.what() + ")");
  }
  return s;
}

}  // namespace skylane::planner
