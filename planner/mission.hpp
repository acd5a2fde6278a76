#pragma once
/// \file
/// \brief The mission file of `skylane approve`: vehicle, box factors, the route (start,
/// waypoints and goal, or a QGroundControl `.plan` mission), altitude limits, departure time or
/// window, the airspace and map files, the orbit files and integrity method, and the planner's
/// settings (schema in the README, "Mission file"). Unknown and missing fields are errors
/// naming them.

#include "geofence/corridor.hpp"
#include "integrity/gnss/error_model.hpp"
#include "integrity/ins/imu_grade.hpp"
#include "integrity/pl_summary.hpp"
#include "maps/geodesy.hpp"
#include "maps/time.hpp"
#include "planner/route_planner.hpp"

#include <nlohmann/json_fwd.hpp>

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief A place of the mission (latitude, longitude in radians).
struct MissionPoint {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
};

/// \brief What the vehicle navigates with, which decides how its protection levels are predicted
/// (README "Mission file", `navigation`; docs/method.md §7.1).
enum class NavigationKind {
  kGnss,      ///< GNSS alone: snapshot RAIM or ARAIM per `integrity.method`
  kGnssIns,   ///< GNSS/INS: the tracker's filter and its fault-mode PLs, predicted along the route
  kReceiver,  ///< a receiver that states its own protection levels (e.g. RTK): constant declared PLs
};

/// \brief "gnss", "gnss_ins", "receiver".
[[nodiscard]] const char* navigationKindName(NavigationKind kind);

/// \brief The mission's `navigation` block.
struct NavigationModel {
  NavigationKind kind = NavigationKind::kGnss;
  integrity::ins::ImuGrade imu = integrity::ins::ImuGrade::kTactical;  ///< kGnssIns: the IMU's grade
  double hpl_m = 0.0, vpl_m = 0.0;  ///< kReceiver: the declared protection levels
};

/// \brief The mission's `policy` block: what the operator requires beyond the fence.
struct MissionPolicy {
  /// Least fraction of route samples whose PLs are within the level-1 limits (HPL ≤ HAL₁ and
  /// VPL ≤ VAL₁); a route below it is rejected naming its worst stretch. None: not required.
  std::optional<double> min_level1_availability;
};

/// \brief Everything a mission file says (paths resolved against the file's folder).
struct Mission {
  std::string source;
  std::string name;
  geofence::Vehicle vehicle;
  double cruise_speed_mps = 10.0;
  double climb_speed_mps = 3.0;
  geofence::BoxLevels levels;
  /// \brief Start, the waypoints to visit in order, and the goal.
  std::vector<MissionPoint> points;
  std::string qgc_plan_file;  ///< the QGroundControl .plan the points came from; empty: the mission file
  double cruise_agl_m = 60.0;
  double min_agl_m = 30.0;
  double max_agl_m = 120.0;
  std::optional<double> max_amsl_m;
  maps::GpsTime departure_earliest;
  maps::GpsTime departure_latest;  ///< = earliest for a fixed departure
  double departure_step_s = 600.0;
  std::vector<std::string> zone_files;
  std::string zone_format = "auto";
  std::string terrain_file;  ///< empty: flat ground at ground_amsl_m
  double ground_amsl_m = 0.0;
  std::string buildings_file;
  std::set<std::string> authorisations;
  std::vector<std::string> orbit_files;
  integrity::IntegrityMethod method = integrity::IntegrityMethod::kRaim;
  double mask_deg = 5.0;
  integrity::ErrorModel model;
  NavigationModel navigation;  ///< how the PLs are predicted (default: GNSS alone)
  MissionPolicy policy;
  double sample_s = 1.0;       ///< prediction step along the route
  double cost_weight = 1.0;    ///< weight of the integrity cost against path length
  double cost_cell_m = 50.0;   ///< grid of the integrity cost field
  PlannerKind planner = PlannerKind::kRrtStar;
  double time_limit_s = 30.0;     ///< per leg, a safety net far above the budget's usual time
  std::uint64_t iterations = 3000;  ///< the planner's iteration budget (reproducible), per leg
  std::uint64_t seed = 1;
  double resolution_m = 2.0;
  bool simplify = true;
  double margin_m = 300.0;     ///< the search box reaches this far beyond start, waypoints and goal
  int max_replans = 2;         ///< per departure, after a violation
};

/// \brief The route of a QGroundControl `.plan` mission.
struct QgcPlanRoute {
  /// \brief Start (the takeoff item's position, else the planned home), every later
  /// positional item in order (home for RETURN_TO_LAUNCH); the last one is the goal. Consecutive
  /// items at the same place count once.
  std::vector<MissionPoint> points;
  /// \brief The NAV_WAYPOINT items' common height when every one is relative to home (frame 3)
  /// or to the terrain (frame 10) and they agree; taken as height above ground.
  std::optional<double> cruise_agl_m;
  std::string cruise_agl_field;  ///< where that height is written (first waypoint's params[6])
};

/// \brief The route of a QGroundControl `.plan` document (`mission.items`, SimpleItems with
/// command 16 NAV_WAYPOINT, 22 NAV_TAKEOFF, 21 NAV_LAND or 20 RETURN_TO_LAUNCH;
/// params[4], params[5] = latitude, longitude in degrees, params[6] = altitude in the item's
/// `frame`: 0 AMSL, 3 relative to home, 10 above terrain; the 5, 6, 11 integer variants too).
/// A takeoff or land item without a position (null, or 0, 0) means "here". Camera, gimbal,
/// region-of-interest, servo and relay commands are skipped; every other command, and
/// ComplexItems (surveys, corridor and structure scans), is refused naming the item.
/// Per-waypoint altitudes are not followed: the planner flies at the mission's cruise AGL.
/// \throws maps::ParseError naming `source`, the JSON path (e.g. "$.mission.items[3].params[4]"),
/// the value and what was expected.
[[nodiscard]] QgcPlanRoute parseQgcPlanRoute(const nlohmann::json& doc, const std::string& source);

/// \brief Reads a JSON file named by a mission (the resolved path); maps::readJsonFile unless a
/// caller (a test, the fuzzer) supplies another.
using JsonFileReader = std::function<nlohmann::json(const std::string& path)>;

/// \brief Parses a mission document; relative file names are resolved against `base_dir`.
/// A `qgc_plan` route is read with `read_json` (maps::readJsonFile when empty).
/// \throws maps::ParseError naming the source (the mission, or the .plan for an error inside
/// it), the field and what was expected.
[[nodiscard]] Mission parseMission(const nlohmann::json& doc, const std::string& source, const std::string& base_dir,
                                   const JsonFileReader& read_json = {});
/// \brief readJsonFile + parseMission.
[[nodiscard]] Mission loadMission(const std::string& path);

}  // namespace skylane::planner
