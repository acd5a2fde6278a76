#pragma once
/// \file
/// \brief A tracked flight's persistent state: what a restarted tracker needs to go on.

#include "maps/time.hpp"

#include <nlohmann/json_fwd.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief A flight's persistent state.
struct FlightState {
  std::optional<maps::GpsTime> last_time;
  std::vector<bool> level1_window, level2_window;  ///< oldest first, at most N each
  std::array<bool, 5> violated{};                  ///< per geofence::Level
  std::array<int, 5> inside_streak{};
  std::optional<maps::GpsTime> last_replan;
  bool stale_reported = false;
  bool arrived = false;       ///< the last fix was within waypoint_radius_m of the goal
  std::size_t next_stop = 1;  ///< index into Mission::points of the next point to reach
  int route_version = 0;      ///< 0: the approved route; n: the n-th accepted replan
  std::uint64_t fixes = 0, rerun_count = 0, replans = 0;
  /// Seconds the flight's clock runs ahead of the stream's since it took a new timeline after a
  /// jump: its fixes move the stream time, and its silence is measured, on the stream's clock.
  double clock_offset_s = 0.0;
  std::optional<maps::GpsTime> jump_candidate;  ///< the last fix refused for a time jump (not stored)
  int jump_count = 0;
  /// Since a replan (or the link's acknowledgement): the vehicle has not yet taken the current
  /// route, and replans are held (tracker.hpp, join_timeout_s).
  std::optional<maps::GpsTime> handoff_since;
  bool handoff_awaits_link = false;  ///< the link's answer is still awaited
  int handoff_inside = 0;            ///< fixes in a row inside the route's level 1 while waiting
};

/// \brief FlightState as JSON and back (the tracker database keeps it).
[[nodiscard]] nlohmann::json flightStateJson(const FlightState& s);
/// \throws maps::ParseError naming `source` for a malformed state.
[[nodiscard]] FlightState parseFlightState(const nlohmann::json& j, const std::string& source);

}  // namespace skylane::planner
