#pragma once
/// \file
/// \brief An approved (or replanned) route as a QGroundControl plan file (`.plan`, file version
/// 1; docs/vehicle_link.md §1), for a ground station to load and upload to the vehicle.
///
/// The mission (version 2): a NAV_TAKEOFF (22) item at the route's first point, one
/// NAV_WAYPOINT (16) per later route point, a NAV_LAND (21) at the goal. Every position item is
/// in frame 0 (MAV_FRAME_GLOBAL: altitude above mean sea level, the route's `alt_amsl_m`; QGC
/// AltitudeMode 2, "Absolute"); the landing altitude is the ground's AMSL height under the goal.
/// A waypoint's acceptance radius (param 2) is the level-1 HAL: a vehicle inside its corridor
/// has reached the point. `cruiseSpeed` and `hoverSpeed` are the mission's cruise speed (a ground
/// station's estimates); a DO_CHANGE_SPEED (178) before each leg whose speed differs from the
/// last one written gives the vehicle the ground speed that flies the leg in its approved time.
///
/// The geoFence (version 2): the level-2 airspace — the union of every segment's box outline
/// (planner::segmentOutline at HAL₂), cut to the union of the keep-in zones active during the
/// flight (the piece holding the route; a hole the keep-in zones leave in it written as an
/// exclusion polygon) — as one inclusion polygon, and every zone the policy counts
/// and that is active at some instant of the flight (departure to the last ETA) as an exclusion
/// polygon or circle, each volume of a zone on its own. Polygons are written clockwise, as the
/// format's description asks. One inclusion polygon, because an autopilot may require the vehicle
/// to be inside every inclusion fence (ArduPilot) rather than inside any (PX4).

#include "planner/approval.hpp"
#include "planner/report_formats.hpp"

#include <nlohmann/json.hpp>

namespace skylane::link {

/// \brief The vehicle the plan is for (MAVLink MAV_AUTOPILOT and MAV_TYPE values).
struct PlanVehicle {
  int firmware_type = 0;  ///< MAV_AUTOPILOT_GENERIC
  int vehicle_type = 2;   ///< MAV_TYPE_QUADROTOR
};

/// \brief The plan document of `report`, a route of `approver`'s mission.
/// \throws std::invalid_argument for a report whose route has fewer than two points.
[[nodiscard]] nlohmann::json qgcPlan(const planner::ApprovalReport& report, const planner::Approver& approver,
                                     const PlanVehicle& vehicle = {});

/// \brief The plan document of a report read back from its file (an approval or a replan's).
/// \throws std::invalid_argument for a route of fewer than two points.
[[nodiscard]] nlohmann::json qgcPlan(planner::ApprovedFlight flight, const planner::Approver& approver,
                                     const PlanVehicle& vehicle = {});

/// \brief The level-2 airspace outline of a route: the union of its segments' boxes
/// (planner::segmentOutline with `hal_m`) in the map frame, counter-clockwise, not closed.
[[nodiscard]] std::vector<Eigen::Vector2d> airspaceOutline(const std::vector<planner::RoutePoint>& route, double hal_m);

}  // namespace skylane::link
