#pragma once
/// \file
/// \brief The approval in exchange formats: GeoJSON (RFC 7946) for any GIS, and ASTM F3548-21
/// operational-intent `Volume4D` objects for a UTM / U-space service (field names as in
/// ASTM F3548-21 Volume4D: volume.outline_polygon.vertices[{lat, lng}], altitude_lower/upper {value,
/// reference "W84", units "M"}, time_start/time_end {value, format "RFC3339"}).

#include "planner/approval.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace skylane::planner {

/// \brief The one JSON form of an approval report (`skylane approve` prints it, `report.json`;
/// README "The report"): decision, reasons, departure, route with ETAs, both box levels,
/// predicted samples, zones, planner statistics and the inputs' SHA-256 digests. Numbers by the
/// rule of maps/json_numbers.hpp.
void to_json(nlohmann::json& j, const ApprovalReport& report);

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

/// \brief One Volume4D per route segment of the given level (1 corridor, 2 airspace): the
/// segment's outline, its heights ± VAL (ellipsoidal, "W84"), and the time from the segment's
/// start ETA − `time_buffer_s` to its end ETA + `time_buffer_s`.
[[nodiscard]] nlohmann::json operationalIntentVolumes(const ApprovalReport& report, const maps::PlaneFrame& frame,
                                                      int level, double time_buffer_s);

/// \brief Seconds an operational intent's volumes reach before and after the route's ETAs.
constexpr double kIntentTimeBuffer_s = 30.0;

/// \brief The operational intent of an approved route (ASTM F3548-21, state "Accepted"): the
/// level-2 volumes as `operational_intent.volumes`, and the level-1 volumes as `corridor_volumes`.
[[nodiscard]] nlohmann::json operationalIntentJson(const ApprovalReport& report, const maps::PlaneFrame& frame);

}  // namespace skylane::planner
