#pragma once
/// \file
/// \brief An approved route's operational intent as ASTM F3548-21 describes it for a UTM /
/// U-space service: `Volume4D` objects — volume.outline_polygon.vertices[{lat, lng}],
/// altitude_lower / altitude_upper {value, reference "W84", units "M"}, time_start / time_end
/// {value, format "RFC3339"} — with one to_json / from_json (numbers by maps/json_numbers.hpp).

#include "planner/approval.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace skylane::planner {

/// \brief One 4-D volume: a polygon (latitude, longitude [rad], counter-clockwise), WGS-84
/// ellipsoidal heights and a time window.
struct Volume4D {
  std::vector<Eigen::Vector2d> outline_rad;
  double altitude_lower_m = 0.0, altitude_upper_m = 0.0;
  maps::GpsTime time_start, time_end;
};

/// \brief The intent: the level-2 volumes (the F3548 `operational_intent`, state "Accepted")
/// and the level-1 volumes (`corridor_volumes`, skylane's addition).
struct OperationalIntent {
  std::vector<Volume4D> volumes;
  std::vector<Volume4D> corridor_volumes;
  std::string state = "Accepted";
  int priority = 0;
};

void to_json(nlohmann::json& j, const Volume4D& v);
/// \throws maps::ParseError naming the JSON path, the value and what was expected.
void from_json(const nlohmann::json& j, Volume4D& v);
void to_json(nlohmann::json& j, const OperationalIntent& oi);
/// \throws maps::ParseError naming the JSON path, the value and what was expected.
void from_json(const nlohmann::json& j, OperationalIntent& oi);

/// \brief One volume per route segment of the given level (1 corridor, 2 airspace): the segment's
/// box outline, its heights ± VAL, and the time from its start ETA − `time_buffer_s` to its end
/// ETA + `time_buffer_s`.
[[nodiscard]] std::vector<Volume4D> routeVolumes(const ApprovalReport& report, const maps::PlaneFrame& frame, int level,
                                                 double time_buffer_s);

/// \brief Seconds an operational intent's volumes reach before and after the route's ETAs.
constexpr double kIntentTimeBuffer_s = 30.0;

/// \brief The operational intent of an approved route.
[[nodiscard]] OperationalIntent operationalIntent(const ApprovalReport& report, const maps::PlaneFrame& frame);

}  // namespace skylane::planner
