#pragma once
/// \file
/// \brief The approval in exchange formats: its report (the one JSON form, and the reader of
/// what tracking acts on) and GeoJSON (RFC 7946) for any GIS.

#include "planner/approval.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace skylane::planner {

/// \brief The one JSON form of an approval report (`skylane approve` prints it, `report.json`;
/// README "The report"): decision, reasons, departure, route with ETAs, both box levels,
/// predicted samples, each level's availability and worst stretch, the navigation the PLs were
/// predicted for, zones, planner statistics and the inputs' SHA-256 digests. Numbers by the
/// rule of maps/json_numbers.hpp.
void to_json(nlohmann::json& j, const ApprovalReport& report);

/// \brief A fraction of samples as a percentage a reader can trust: "0 %" and "100 %" only
/// when exact, one decimal where rounding would reach them ("99.7 %", "0.4 %"), else whole.
[[nodiscard]] std::string availabilityPercent(double fraction);

/// \brief The one-line verdict of an approval (`skylane approve` prints it on stderr): the
/// decision (and a rejection's first reason), the corridor's limits (±HAL₁ / ±VAL₁) and the share
/// of route samples whose PLs are within them, and what a shortfall means in flight, e.g.
/// "APPROVED — corridor ±1.8 m / ±2.0 m held at 0 % of samples: expect a monitoring rerun at
/// every fix".
[[nodiscard]] std::string approvalSummary(const ApprovalReport& report);

/// \brief What live tracking needs of an approval report.
struct ApprovedFlight {
  std::string report_source;   ///< the report file
  std::string mission_name;
  std::string mission_source;  ///< the mission file as the report names it
  std::string mission_source_absolute;  ///< its absolute path at approval time (may be empty)
  std::string mission_sha256;  ///< its digest at approval time (empty when the report has none)
  bool approved = false;
  maps::GpsTime departure;
  std::vector<RoutePoint> route;  ///< lat, lon, h_ell, AMSL, ETA (xyz left for the caller's frame)
  geofence::AlertLimits level1, level2;
};

/// \brief Reads the fields of a report's JSON form that tracking and an autopilot link act on.
/// \throws maps::ParseError naming `source`, the JSON path, the value and what was expected.
[[nodiscard]] ApprovedFlight parseApprovalReport(const nlohmann::json& doc, const std::string& source);

/// \brief parseApprovalReport() of a document with no file name ("approval report").
void from_json(const nlohmann::json& j, ApprovedFlight& f);

/// \brief The footprint of one segment's box in the map frame: the rectangle around a→b
/// widened by `hal_m` on each side and lengthened by `hal_m` at both ends, so that it also
/// covers the joint cylinders (radius hal_m) at a and b. Counter-clockwise.
[[nodiscard]] std::vector<Eigen::Vector2d> segmentOutline(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double hal_m);

/// \brief A FeatureCollection: the route (LineString, heights AMSL), its points with ETA, both
/// box levels (one Polygon per segment), and every reason that has a place (Point).
[[nodiscard]] nlohmann::json routeGeoJson(const ApprovalReport& report, const Mission& mission,
                                          const maps::PlaneFrame& frame);
/// \brief The same (route, points, boxes; no reasons) for a flight's route as tracking holds it
/// (after a replan, the new one).
[[nodiscard]] nlohmann::json routeGeoJson(const ApprovedFlight& flight, const Mission& mission, const maps::PlaneFrame& frame);

/// (The operational intent, ASTM F3548-21 Volume4D objects, is planner/operational_intent.hpp.)

}  // namespace skylane::planner
