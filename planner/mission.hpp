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

/// \brief What a route point's height is measured from (a QGroundControl item's MAV_FRAME).
enum class HeightReference {
  kAboveGround,  ///< frame 10 (11): above the terrain under the point
  kAboveHome,    ///< frame 3 (6): above the ground at the home (Mission::qgc_home)
  kAmsl,         ///< frame 0 (5): above mean sea level (EGM96)
};

/// \brief A route point's own height, as a plan item writes it.
struct PointHeight {
  HeightReference reference = HeightReference::kAboveGround;
  double value_m = 0.0;
  std::string field;  ///< where it is written, e.g. "$.mission.items[3].params[6]"
};

/// \brief How the vehicle reaches a route point and what it does there (a QGroundControl plan's
/// items; a mission-file route has none: cruise AGL, cruise speed, no hover).
struct PointFlight {
  std::optional<PointHeight> height;  ///< none: the mission's cruise AGL
  /// Ground speed of the leg arriving at the point; none: the vehicle's cruise speed.
  std::optional<double> speed_mps;
  std::string speed_field;  ///< where that speed was set (a DO_CHANGE_SPEED's params[1])
  double hover_s = 0.0;     ///< time the vehicle stays at the point after arriving
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
  /// \brief Per point of `points`: its height, the speed of the leg to it and its hover (from the
  /// .plan); empty for a mission-file route (every point at cruise AGL and speed, no hover).
  std::vector<PointFlight> point_flights;
  /// \brief The place the plan's heights relative to home are measured from (its planned home,
  /// else the start); none for a mission-file route.
  std::optional<MissionPoint> qgc_home;
  double cruise_agl_m = 60.0;
  double min_agl_m = 30.0;
  double max_agl_m = 120.0;
  std::optional<double> max_amsl_m;
  maps::GpsTime departure_earliest;
  maps::GpsTime departure_latest;  ///< = earliest for a fixed departure
  double departure_step_s = 600.0;
  /// \brief The `zones` files, then the .plan when its geoFence has fences and `zones` does not
  /// already name it (its fences are zones: exclusions prohibited, inclusions keep-in).
  std::vector<std::string> zone_files;
  std::string zone_format = "auto";  ///< of the `zones` files; the .plan is always read as one
  std::string terrain_file;  ///< empty: flat ground at ground_amsl_m
  double ground_amsl_m = 0.0;
  std::string buildings_file;
  std::set<std::string> authorisations;
  std::vector<std::string> orbit_files;
  integrity::IntegrityMethod method = integrity::IntegrityMethod::kRaim;
  bool with_exclusion = false;  ///< `integrity.fde`: the predicted PLs of a user who excludes
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
  /// When the OMPL search finds no exact path, search a lattice seed and refine it
  /// (planner/lattice_search.hpp); "lattice" as the algorithm searches it at once.
  bool lattice_fallback = true;
  double margin_m = 300.0;     ///< the search box reaches this far beyond start, waypoints and goal
  int max_replans = 2;         ///< per departure, after a violation
};

/// \brief The fastest ground speed a plan's DO_CHANGE_SPEED may set [m/s] (144 km/h: beyond the
/// small drones this planner is for; a larger value is taken for a typing error).
constexpr double kMaxPlanSpeed_mps = 40.0;
/// \brief The longest hover one plan item may ask for [s]: one hour, beyond any multirotor's
/// endurance.
constexpr double kMaxPlanHover_s = 3600.0;

/// \brief The route of a QGroundControl `.plan` mission.
struct QgcPlanRoute {
  /// \brief Start (the takeoff item's position, else the planned home), every later
  /// positional item in order (home for RETURN_TO_LAUNCH); the last one is the goal. Consecutive
  /// items at the same place and height count once.
  std::vector<MissionPoint> points;
  std::vector<PointFlight> flights;  ///< per point: height, speed of the leg to it, hover there
  MissionPoint home;                 ///< the planned home, else the start: frame-3 heights' reference
  bool has_geofence = false;         ///< `geoFence` holds polygons or circles (read as zones)
  /// \brief The NAV_WAYPOINT items' common height when every one is relative to home (frame 3)
  /// or to the terrain (frame 10) and they agree; taken as height above ground (the mission's
  /// cruise height when within its limits).
  std::optional<double> cruise_agl_m;
  std::string cruise_agl_field;  ///< where that height is written (first waypoint's params[6])
};

/// \brief The route of a QGroundControl `.plan` document: `mission.items` in order.
///
/// Positional SimpleItems (params[4], params[5] = latitude, longitude in degrees, params[6] =
/// altitude in the item's `frame`: 0 AMSL, 3 relative to home, 10 above terrain; the 5, 6, 11
/// integer variants too) make the route's points, each at its own height:
/// - 22 NAV_TAKEOFF: the start, at its altitude (without a position, null or 0, 0: the planned
///   home). Without a takeoff item the start is the planned home at the mission's cruise AGL.
/// - 16 NAV_WAYPOINT: a point at its altitude; params[0] (hold time, s) > 0 hovers there.
/// - 19 NAV_LOITER_TIME: a point at its altitude (none: where the vehicle is) and a hover of
///   params[0] seconds there.
/// - 21 NAV_LAND (position optional) and 20 RETURN_TO_LAUNCH (to the planned home): the goal, at
///   the height of the point before (the descent to the ground is not planned, as the climb from
///   it is not).
/// Timing items: 178 DO_CHANGE_SPEED (params[1] m/s, -1 = no change; params[0] 0 airspeed or
/// 1 ground speed, both taken as the ground speed of the legs after it; 0 < speed ≤
/// kMaxPlanSpeed_mps) and 93 NAV_DELAY (params[0] seconds, a hover where the vehicle is; the
/// time-of-day form, params[0] = -1, is refused). Hovers are 0 … kMaxPlanHover_s seconds.
/// Camera, gimbal, region-of-interest, servo and relay commands are skipped; every other command
/// (DO_JUMP, unlimited or turn loiters, VTOL items, conditions …) and ComplexItems (surveys,
/// corridor and structure scans) are refused naming the item. The heights are checked against
/// the mission's limits by the approval (it knows the terrain). `cruise_agl_m` is the
/// waypoints' common height when they agree (then the mission's cruise height, for the integrity
/// cost field and a start without takeoff item).
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
