#include "planner/mission.hpp"

#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <optional>
#include <system_error>
#include <utility>

namespace skylane::planner {

using maps::JsonNode;

namespace {

/// The latitude limit of mission points (the planner's local frame is not made for the poles).
constexpr double kMaxMissionLatitude_deg = 89.0;

// Bounds of the numbers that become geometry (a margin of 1e308 m made the planner's bounds and
// the terrain look-ups NaN): far above any UAS, far below a double's range.
constexpr double kMaxVehicleSize_m = 1000.0;   ///< any UAS is smaller (the largest spans ~80 m)
constexpr double kMaxSpeed_mps = 300.0;        ///< below the speed of sound
constexpr double kMaxPlannerLength_m = 10e3;   ///< planner resolution and clearance margin
constexpr double kMaxTimeLimit_s = 86400.0;    ///< one day of planning
constexpr double kMaxBoxFactor = 1e4;          ///< k1, k2 with override_ranges (the ranges are 1.1–1.3, 100–1000)
constexpr double kMaxHeightAgl_m = 20000.0;    ///< above any UAS's ceiling

MissionPoint point(const JsonNode& n) {
  n.requireKnownFields({"lat", "lon"});
  const double lat = n.at("lat").number(), lon = n.at("lon").number();
  if (std::abs(lat) > kMaxMissionLatitude_deg) n.at("lat").fail("a latitude within ±89°");
  if (std::abs(lon) > 180.0) n.at("lon").fail("a longitude within ±180°");
  return {maps::deg2rad(lat), maps::deg2rad(lon)};
}

maps::GpsTime time(const JsonNode& n) {
  const auto t = maps::parseRfc3339(n.str());
  if (!t) n.fail("an RFC 3339 UTC time such as \"2026-11-24T14:00:00Z\"");
  return *t;
}

std::string resolve(const std::string& base_dir, const std::string& name) {
  std::filesystem::path p(name);
  if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
  return p.lexically_normal().string();
}

std::vector<std::string> files(const JsonNode& n, const std::string& base_dir) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n.array().size(); ++i) out.push_back(resolve(base_dir, n.item(i).str()));
  return out;
}

// --- QGroundControl .plan ----------------------------------------------------------------------

/// MAVLink MAV_CMD values of the mission items a route is made of.
enum QgcCommand : int {
  kNavWaypoint = 16,
  kNavLoiterTime = 19,
  kNavReturnToLaunch = 20,
  kNavLand = 21,
  kNavTakeoff = 22,
  kNavDelay = 93,
  kDoChangeSpeed = 178,
};

/// \brief A command the route cannot honour, with why (the refusal names it).
struct RefusedCommand {
  int command;
  const char* name;
  const char* why;
};

/// Commands met in real plans that change the route or its timing in ways a planned route cannot
/// follow: refused with the reason. Any other unknown command gets the general refusal.
constexpr RefusedCommand kRefusedCommands[] = {
    {17, "NAV_LOITER_UNLIM", "it loiters without end, so the goal is never reached"},
    {18, "NAV_LOITER_TURNS", "its duration depends on the vehicle's turn radius: use NAV_LOITER_TIME"},
    {31, "NAV_LOITER_TO_ALT", "its duration depends on the vehicle's climb: use NAV_LOITER_TIME"},
    {84, "NAV_VTOL_TAKEOFF", "VTOL transitions are not planned"},
    {85, "NAV_VTOL_LAND", "VTOL transitions are not planned"},
    {112, "CONDITION_DELAY", "conditions are not planned: use NAV_DELAY"},
    {114, "CONDITION_DISTANCE", "conditions are not planned"},
    {177, "DO_JUMP", "it repeats part of the mission: unroll the loop into waypoints"},
    {179, "DO_SET_HOME", "it moves the home that relative heights and RETURN_TO_LAUNCH refer to"},
    {189, "DO_LAND_START", "landing sequences are not planned: end with NAV_LAND"},
};

/// Commands that only work a payload (camera, gimbal, region of interest, servo, relay) and
/// neither move the vehicle nor make it wait: skipped. MAVLink common.xml numbers.
constexpr int kPayloadCommands[] = {
    181, 182, 183, 184,            // DO_SET_RELAY, DO_REPEAT_RELAY, DO_SET_SERVO, DO_REPEAT_SERVO
    195, 196, 197, 201,            // DO_SET_ROI_LOCATION, _WPNEXT_OFFSET, _NONE, DO_SET_ROI
    202, 203, 204, 205, 206, 214,  // DO_DIGICAM_CONFIGURE/_CONTROL, DO_MOUNT_CONFIGURE/_CONTROL, cam trigger
    530, 531, 532,                 // SET_CAMERA_MODE, _ZOOM, _FOCUS
    1000, 1001,                    // DO_GIMBAL_MANAGER_PITCHYAW, _CONFIGURE
    2000, 2001, 2003, 2500, 2501,  // IMAGE_START/STOP_CAPTURE, DO_TRIGGER_CONTROL, VIDEO_START/STOP_CAPTURE
};

/// MAV_FRAME values QGroundControl writes for positions, with their integer-coordinate twins.
enum class QgcAltitudeReference { kAmsl, kRelativeToHome, kTerrain };

/// Waypoint heights closer than this are "the same" (QGroundControl keeps them as typed; this
/// only absorbs a decimal round trip).
constexpr double kSameAltitudeTolerance_m = 1e-3;

const char* commandName(int command) {
  switch (command) {
    case kNavWaypoint: return "NAV_WAYPOINT";
    case kNavLoiterTime: return "NAV_LOITER_TIME";
    case kNavDelay: return "NAV_DELAY";
    case kDoChangeSpeed: return "DO_CHANGE_SPEED";
    case kNavReturnToLaunch: return "RETURN_TO_LAUNCH";
    case kNavLand: return "NAV_LAND";
    case kNavTakeoff: return "NAV_TAKEOFF";
    default: return "?";
  }
}

QgcAltitudeReference altitudeReference(const JsonNode& frame) {
  const double f = frame.number();
  if (f == 0 || f == 5) return QgcAltitudeReference::kAmsl;
  if (f == 3 || f == 6) return QgcAltitudeReference::kRelativeToHome;
  if (f == 10 || f == 11) return QgcAltitudeReference::kTerrain;
  frame.fail("a MAV_FRAME for a position: 0 (AMSL), 3 (relative to home) or 10 (terrain), or 5, 6, 11");
}

/// params[k] of an item, a finite number ("what" says what it stands for).
double param(const JsonNode& params, std::size_t k, const std::string& what) {
  const JsonNode p = params.item(k);
  if (!p.j.is_number()) p.fail(what + " (a number)");
  return p.number();
}

/// A latitude and longitude in degrees written at lat, lon → MissionPoint.
MissionPoint qgcPosition(const JsonNode& lat_node, const JsonNode& lon_node) {
  const char* lat_what = "a latitude in degrees within ±89°";
  const char* lon_what = "a longitude in degrees within ±180°";
  if (!lat_node.j.is_number()) lat_node.fail(lat_what);
  if (!lon_node.j.is_number()) lon_node.fail(lon_what);
  const double lat = lat_node.number(), lon = lon_node.number();
  if (!(std::abs(lat) <= kMaxMissionLatitude_deg)) lat_node.fail(lat_what);
  if (!(std::abs(lon) <= 180.0)) lon_node.fail(lon_what);
  return {maps::deg2rad(lat), maps::deg2rad(lon)};
}

/// The position of a takeoff or land item, or none when it has none: both null (QGroundControl
/// writes NaN as null), or both exactly 0 (ArduPilot's "here").
std::optional<MissionPoint> optionalPosition(const JsonNode& params) {
  const JsonNode lat = params.item(4), lon = params.item(5);
  if (lat.j.is_null() && lon.j.is_null()) return std::nullopt;
  if (lat.j.is_number() && lon.j.is_number() && lat.j.get<double>() == 0.0 && lon.j.get<double>() == 0.0) {
    return std::nullopt;
  }
  return qgcPosition(lat, lon);
}

bool samePlace(const MissionPoint& a, const MissionPoint& b) { return a.lat_rad == b.lat_rad && a.lon_rad == b.lon_rad; }

bool sameHeight(const std::optional<PointHeight>& a, const std::optional<PointHeight>& b) {
  if (!a || !b) return !a && !b;
  return a->reference == b->reference && std::abs(a->value_m - b->value_m) <= kSameAltitudeTolerance_m;
}

HeightReference heightReference(QgcAltitudeReference r) {
  switch (r) {
    case QgcAltitudeReference::kAmsl: return HeightReference::kAmsl;
    case QgcAltitudeReference::kRelativeToHome: return HeightReference::kAboveHome;
    case QgcAltitudeReference::kTerrain: return HeightReference::kAboveGround;
  }
  return HeightReference::kAboveGround;
}

/// \brief A positional item's own height: params[6] in its frame.
PointHeight itemHeight(const JsonNode& params, QgcAltitudeReference reference) {
  return {heightReference(reference), param(params, 6, "an altitude in metres"), params.path + "[6]"};
}

/// \brief A hover time in seconds at params[k]: 0 … kMaxPlanHover_s (null counts as 0 when
/// `null_is_zero`, as QGroundControl writes an unset hold time).
double hoverSeconds(const JsonNode& params, std::size_t k, bool null_is_zero) {
  const JsonNode p = params.item(k);
  if (null_is_zero && p.j.is_null()) return 0.0;
  const std::string what = "a time in seconds, 0 … " + maps::quoteJson(nlohmann::json(kMaxPlanHover_s));
  if (!p.j.is_number()) p.fail(what);
  const double s = p.number();
  if (!(s >= 0.0 && s <= kMaxPlanHover_s)) p.fail(what);
  return s;
}

/// \brief Whether the plan has fences to read as zones: a `geoFence` with polygons or circles
/// (or one that is not as expected: the zone loader then names what is wrong).
bool hasGeofence(const nlohmann::json& doc) {
  if (!doc.is_object()) return false;
  const auto fence = doc.find("geoFence");
  if (fence == doc.end()) return false;
  if (!fence->is_object()) return true;
  for (const char* key : {"polygons", "circles"}) {
    const auto list = fence->find(key);
    if (list != fence->end() && !(list->is_array() && list->empty())) return true;
  }
  return false;
}

/// \brief The walk through a plan's items: the route so far and what it has seen.
struct PlanWalk {
  QgcPlanRoute route;
  std::optional<MissionPoint> home;  ///< mission.plannedHomePosition
  std::string home_path;             ///< where the planned home is written
  std::optional<MissionPoint> start;
  bool returned = false;  ///< a RETURN_TO_LAUNCH was seen: the mission ends there
  std::optional<double> common_height_m;
  bool heights_agree = true;
  std::optional<double> speed_mps;  ///< the last DO_CHANGE_SPEED's, for the legs after it
  std::string speed_field;
  double pending_hover_s = 0.0;  ///< NAV_DELAY before the route has a point: the start's hover
};

/// \brief The `mission` object of a QGroundControl plan document.
JsonNode planMission(const JsonNode& root) {
  if (!root.j.is_object()) root.fail("a QGroundControl plan (an object with fileType \"Plan\" and a mission)");
  if (root.has("fileType") && !(root.at("fileType").j.is_string() && root.at("fileType").str() == "Plan")) {
    root.at("fileType").fail("\"Plan\" (a QGroundControl .plan file)");
  }
  const JsonNode mission = root.at("mission");
  if (!mission.j.is_object()) mission.fail("an object with items and plannedHomePosition");
  return mission;
}

std::optional<MissionPoint> plannedHome(const JsonNode& mission) {
  if (!mission.has("plannedHomePosition")) return std::nullopt;
  const JsonNode h = mission.at("plannedHomePosition");
  if (h.array().size() < 2) h.fail("[lat, lon, alt] in degrees and metres");
  return qgcPosition(h.item(0), h.item(1));
}

/// \brief The planned home, which `item` needs because `why`; an error when the plan has none.
MissionPoint needHome(const PlanWalk& w, const JsonNode& item, const char* why) {
  if (w.home) return *w.home;
  throw maps::ParseError(item.source, 0, w.home_path, "",
                         std::string("[lat, lon, alt] in degrees and metres (") + why + " at " + item.path + ")");
}

/// \brief Appends a point at `height`, reached at the walk's current speed, unless it is where
/// (and as high as) the route already is.
void addPoint(PlanWalk& w, const MissionPoint& p, const std::optional<PointHeight>& height) {
  if (!w.route.points.empty() && samePlace(w.route.points.back(), p) && sameHeight(w.route.flights.back().height, height)) {
    return;
  }
  PointFlight f;
  f.height = height;
  f.speed_mps = w.speed_mps;
  f.speed_field = w.speed_field;
  if (w.route.points.empty()) std::swap(f.hover_s, w.pending_hover_s);
  w.route.points.push_back(p);
  w.route.flights.push_back(std::move(f));
}

/// \brief The height of the route's last point (a land or return item keeps it).
std::optional<PointHeight> lastHeight(const PlanWalk& w) {
  return w.route.flights.empty() ? std::nullopt : w.route.flights.back().height;
}

/// \brief The vehicle stays where it is for `hover_s` (before the first point: at the start).
void addHover(PlanWalk& w, double hover_s) {
  if (w.route.flights.empty()) {
    w.pending_hover_s += hover_s;
  } else {
    w.route.flights.back().hover_s += hover_s;
  }
}

/// \brief The MAVLink command of a SimpleItem that makes the route; none for a payload command
/// (skipped). An error for a ComplexItem or any other command.
std::optional<int> routeCommand(const JsonNode& item) {
  if (!item.j.is_object()) item.fail("a mission item (an object with type SimpleItem)");
  const std::string type = item.at("type").str();
  if (type == "ComplexItem") {
    const std::string kind = item.has("complexItemType") ? maps::quoteJson(item.at("complexItemType").j) : "complex";
    throw maps::ParseError(item.source, 0, item.path, kind + " ComplexItem",
                           "a SimpleItem (surveys, corridor and structure scans are not supported: "
                           "convert the pattern to waypoints in QGroundControl, or plan its corners as waypoints)");
  }
  if (type != "SimpleItem") item.at("type").fail("SimpleItem");
  const JsonNode command_node = item.at("command");
  const double command_value = command_node.number();
  if (command_value != std::floor(command_value) || std::abs(command_value) > 1e6) {
    command_node.fail("a MAVLink command number");
  }
  const int command = static_cast<int>(command_value);
  if (std::find(std::begin(kPayloadCommands), std::end(kPayloadCommands), command) != std::end(kPayloadCommands)) {
    return std::nullopt;
  }
  const std::string supported =
      "16 NAV_WAYPOINT, 19 NAV_LOITER_TIME, 22 NAV_TAKEOFF, 21 NAV_LAND, 20 RETURN_TO_LAUNCH, 93 NAV_DELAY or "
      "178 DO_CHANGE_SPEED (or a camera, gimbal, ROI, servo or relay command, which is skipped)";
  for (const RefusedCommand& r : kRefusedCommands) {
    if (r.command == command) command_node.fail(supported + "; " + r.name + " is not supported: " + r.why);
  }
  if (command != kNavWaypoint && command != kNavTakeoff && command != kNavLand && command != kNavReturnToLaunch &&
      command != kNavLoiterTime && command != kNavDelay && command != kDoChangeSpeed) {
    command_node.fail(supported + "; other commands change the route or its timing and are not supported");
  }
  return command;
}

void addReturnToLaunch(PlanWalk& w, const JsonNode& item) {
  if (!w.start) w.start = needHome(w, item, "RETURN_TO_LAUNCH flies to it");
  if (w.route.points.empty()) addPoint(w, *w.start, std::nullopt);
  addPoint(w, needHome(w, item, "RETURN_TO_LAUNCH flies to it"), lastHeight(w));
  w.returned = true;
}

void addTakeoff(PlanWalk& w, const JsonNode& item, const JsonNode& params) {
  if (w.start) item.fail("a NAV_TAKEOFF before every other positional item");
  const QgcAltitudeReference reference = altitudeReference(item.at("frame"));
  const auto p = optionalPosition(params);
  w.start = p ? *p : needHome(w, item, "the start when NAV_TAKEOFF gives no position");
  addPoint(w, *w.start, itemHeight(params, reference));
}

/// \brief Without a takeoff item the route starts at the planned home (at cruise AGL).
void requireStart(PlanWalk& w, const JsonNode& item) {
  if (w.start) return;
  w.start = needHome(w, item, "the start when no NAV_TAKEOFF gives a position");
  addPoint(w, *w.start, std::nullopt);
}

/// \brief A DO_CHANGE_SPEED: params[1] (m/s, -1 = no change) for the legs after it; params[0]
/// airspeed (0) or ground speed (1), both taken as ground speed.
void changeSpeed(PlanWalk& w, const JsonNode& params) {
  const JsonNode type = params.item(0), speed = params.item(1);
  if (!type.j.is_number() || (type.number() != 0.0 && type.number() != 1.0)) {
    type.fail("a speed type 0 (airspeed) or 1 (ground speed); climb and descent speed changes (2, 3) are not "
              "supported");
  }
  const std::string what = "a speed in m/s, > 0 and ≤ " + maps::quoteJson(nlohmann::json(kMaxPlanSpeed_mps)) +
                           " (or -1: no change)";
  if (!speed.j.is_number()) speed.fail(what);
  const double v = speed.number();
  if (v == -1.0) return;
  if (!(v > 0.0 && v <= kMaxPlanSpeed_mps)) speed.fail(what);
  w.speed_mps = v;
  w.speed_field = speed.path;
}

/// \brief A NAV_DELAY: params[0] seconds of hover where the vehicle is. The time-of-day form
/// (params[0] = -1, then hour, minute, second) depends on the departure: refused.
void addDelay(PlanWalk& w, const JsonNode& params) {
  const JsonNode delay = params.item(0);
  if (delay.j.is_number() && delay.j.get<double>() == -1.0) {
    delay.fail("a delay in seconds (the time-of-day form, params[0] = -1 with hour, minute and second, is not "
               "supported: give the wait in seconds)");
  }
  addHover(w, hoverSeconds(params, 0, false));
}

/// \brief A NAV_LOITER_TIME: a point at its place and height (none: where the vehicle is) and a
/// hover of params[0] seconds there.
void addLoiterTime(PlanWalk& w, const JsonNode& params, QgcAltitudeReference reference) {
  const double hover_s = hoverSeconds(params, 0, false);
  if (const auto p = optionalPosition(params)) addPoint(w, *p, itemHeight(params, reference));
  addHover(w, hover_s);
}

/// \brief A NAV_WAYPOINT: its place at its height, its hold time (params[0]) as a hover, and its
/// height towards the route's common height.
void addWaypoint(PlanWalk& w, const JsonNode& params, QgcAltitudeReference reference) {
  const JsonNode lat = params.item(4), lon = params.item(5);
  if (lat.j.is_number() && lon.j.is_number() && lat.j.get<double>() == 0.0 && lon.j.get<double>() == 0.0) {
    lat.fail("a waypoint position (0, 0 means \"here\" to some autopilots: give the place)");
  }
  const MissionPoint place = qgcPosition(lat, lon);
  const PointHeight height = itemHeight(params, reference);
  addPoint(w, place, height);
  addHover(w, hoverSeconds(params, 0, true));
  const double height_m = height.value_m;
  if (reference == QgcAltitudeReference::kAmsl) {
    w.heights_agree = false;
  } else if (!w.common_height_m) {
    w.common_height_m = height_m;
    w.route.cruise_agl_field = params.path + "[6]";
  } else if (std::abs(height_m - *w.common_height_m) > kSameAltitudeTolerance_m) {
    w.heights_agree = false;
  }
}

/// \brief A waypoint, a timed loiter or a land item, after the start.
void addPositionalItem(PlanWalk& w, const JsonNode& item, const JsonNode& params, int command) {
  requireStart(w, item);
  const QgcAltitudeReference reference = altitudeReference(item.at("frame"));
  if (command == kNavLand) {
    if (const auto p = optionalPosition(params)) addPoint(w, *p, lastHeight(w));
  } else if (command == kNavLoiterTime) {
    addLoiterTime(w, params, reference);
  } else {
    addWaypoint(w, params, reference);
  }
}

/// \brief One route or timing item (a supported command) added to the walk.
void addRouteItem(PlanWalk& w, const JsonNode& item, int command) {
  if (w.returned) {
    item.fail(std::string("no ") + commandName(command) + " after RETURN_TO_LAUNCH (the vehicle has gone home)");
  }
  if (command == kNavReturnToLaunch) {
    addReturnToLaunch(w, item);
    return;
  }
  const JsonNode params = item.at("params");
  if (params.array().size() < 7) {
    params.fail("7 parameters [param1 … param7]: params[4], params[5], params[6] = latitude, longitude, altitude");
  }
  if (command == kNavTakeoff) {
    addTakeoff(w, item, params);
  } else if (command == kDoChangeSpeed) {
    changeSpeed(w, params);
  } else if (command == kNavDelay) {
    addDelay(w, params);
  } else {
    addPositionalItem(w, item, params, command);
  }
}

/// \brief The mission's top-level fields, checked against the known ones.
void requireMissionFields(const JsonNode& root) {
  root.requireKnownFields({"name", "vehicle", "k1", "k2", "start", "goal", "waypoints", "qgc_plan", "altitude",
                           "departure", "departure_window", "zones", "zone_format", "terrain", "ground_amsl_m",
                           "buildings", "authorisations", "orbits", "integrity", "navigation", "policy", "planner"});
}

void readVehicle(const JsonNode& v, Mission& m) {
  v.requireKnownFields({"lateral_m", "longitudinal_m", "height_m", "cruise_speed_mps", "climb_speed_mps"});
  m.vehicle.lateral_m = v.at("lateral_m").positiveUpTo(kMaxVehicleSize_m, "m");
  m.vehicle.longitudinal_m = v.at("longitudinal_m").positiveUpTo(kMaxVehicleSize_m, "m");
  if (v.has("height_m")) m.vehicle.height_m = v.at("height_m").positiveUpTo(kMaxVehicleSize_m, "m");
  m.cruise_speed_mps = v.at("cruise_speed_mps").positiveUpTo(kMaxSpeed_mps, "m/s");
  if (v.has("climb_speed_mps")) m.climb_speed_mps = v.at("climb_speed_mps").positiveUpTo(kMaxSpeed_mps, "m/s");
}

/// \brief The route: start, waypoints and goal here, or a QGroundControl .plan; exactly one of
/// the two.
void requireOneRoute(const JsonNode& root) {
  std::string given;
  for (const char* key : {"start", "waypoints", "goal"}) {
    if (root.has(key)) given += (given.empty() ? "$." : ", $.") + std::string(key);
  }
  if (root.has("qgc_plan") && !given.empty()) {
    throw maps::ParseError(root.source, 0, "$.qgc_plan", maps::quoteJson(root.at("qgc_plan").j),
                           "either qgc_plan or start/waypoints/goal, not both (" + given + " also given)");
  }
  if (!root.has("qgc_plan") && given.empty()) {
    throw maps::ParseError(root.source, 0, "$.start", "",
                           "a route: start and goal (waypoints optional), or qgc_plan naming a QGroundControl .plan");
  }
}

/// \brief The route of the .plan file named by `qgc_plan`, read with `read_json`.
QgcPlanRoute readQgcPlan(const JsonNode& q, const std::string& base_dir, const JsonFileReader& read_json,
                         Mission& m) {
  const std::string name = q.str();
  if (name.empty()) q.fail("the name of a QGroundControl .plan file");
  m.qgc_plan_file = resolve(base_dir, name);
  nlohmann::json plan;
  try {
    plan = read_json ? read_json(m.qgc_plan_file) : maps::readJsonFile(m.qgc_plan_file);
  } catch (const maps::ParseError& e) {
    if (e.source() != m.qgc_plan_file || e.field() != "file") throw;
    q.fail("a readable QGroundControl .plan file (" + m.qgc_plan_file + " cannot be read)");
  }
  QgcPlanRoute plan_route = parseQgcPlanRoute(plan, m.qgc_plan_file);
  m.points = plan_route.points;
  m.point_flights = plan_route.flights;
  m.qgc_home = plan_route.home;
  return plan_route;
}

/// \brief The mission's points; the .plan's route when the mission names one.
std::optional<QgcPlanRoute> readRoute(const JsonNode& root, const std::string& base_dir,
                                      const JsonFileReader& read_json, Mission& m) {
  requireOneRoute(root);
  if (root.has("qgc_plan")) return readQgcPlan(root.at("qgc_plan"), base_dir, read_json, m);
  m.points.push_back(point(root.at("start")));
  if (root.has("waypoints")) {
    const JsonNode w = root.at("waypoints");
    for (std::size_t i = 0; i < w.array().size(); ++i) m.points.push_back(point(w.item(i)));
  }
  m.points.push_back(point(root.at("goal")));
  return std::nullopt;
}

/// \brief The .plan joins the zone files when its geoFence has fences, unless `zones` names it.
void addPlanFence(const std::optional<QgcPlanRoute>& plan_route, Mission& m) {
  if (!plan_route || !plan_route->has_geofence) return;
  for (const std::string& f : m.zone_files) {
    std::error_code ec;
    if (f == m.qgc_plan_file || std::filesystem::equivalent(f, m.qgc_plan_file, ec)) return;
  }
  m.zone_files.push_back(m.qgc_plan_file);
}

/// \brief The altitude block; a .plan's common waypoint height is the cruise height unless the
/// mission gives one.
void readAltitudes(const JsonNode& root, const std::optional<QgcPlanRoute>& plan_route, Mission& m) {
  bool cruise_given = false;
  if (root.has("altitude")) {
    const JsonNode a = root.at("altitude");
    a.requireKnownFields({"cruise_agl_m", "min_agl_m", "max_agl_m", "max_amsl_m"});
    cruise_given = a.has("cruise_agl_m");
    if (cruise_given) m.cruise_agl_m = a.at("cruise_agl_m").positiveUpTo(kMaxHeightAgl_m, "m");
    if (a.has("min_agl_m")) m.min_agl_m = a.at("min_agl_m").number();
    if (a.has("max_agl_m")) m.max_agl_m = a.at("max_agl_m").positiveUpTo(kMaxHeightAgl_m, "m");
    if (a.has("max_amsl_m")) m.max_amsl_m = a.at("max_amsl_m").number();
  }
  // The plan's common height is the cruise height when it lies within the limits; each point's
  // own height is checked against them by the approval (which knows the ground).
  if (plan_route && plan_route->cruise_agl_m && !cruise_given) {
    const double h = *plan_route->cruise_agl_m;
    if (h > 0.0 && m.min_agl_m <= h && h <= m.max_agl_m) m.cruise_agl_m = h;
  }
  if (root.has("altitude") && !(m.min_agl_m <= m.cruise_agl_m && m.cruise_agl_m <= m.max_agl_m)) {
    root.at("altitude").fail("min_agl_m ≤ cruise_agl_m ≤ max_agl_m");
  }
}

void readDeparture(const JsonNode& root, Mission& m) {
  m.departure_earliest = m.departure_latest = time(root.at("departure"));
  if (root.has("departure_window")) {
    const JsonNode w = root.at("departure_window");
    w.requireKnownFields({"latest", "step_s"});
    m.departure_latest = time(w.at("latest"));
    if (m.departure_latest - m.departure_earliest < 0) w.at("latest").fail("a time not before departure");
    if (w.has("step_s")) m.departure_step_s = w.at("step_s").positiveUpTo(kMaxTimeLimit_s, "s");
  }
}

/// \brief Zones, terrain or ground height, buildings, authorisations and orbits.
void readDataFiles(const JsonNode& root, const std::string& base_dir, Mission& m) {
  if (root.has("zones")) m.zone_files = files(root.at("zones"), base_dir);
  if (root.has("zone_format")) m.zone_format = root.at("zone_format").str();
  if (root.has("terrain") && root.has("ground_amsl_m")) root.fail("an object with at most one of terrain and ground_amsl_m");
  if (root.has("terrain")) m.terrain_file = resolve(base_dir, root.at("terrain").str());
  if (root.has("ground_amsl_m")) m.ground_amsl_m = root.at("ground_amsl_m").number();
  if (root.has("buildings")) m.buildings_file = resolve(base_dir, root.at("buildings").str());
  if (root.has("authorisations")) {
    const JsonNode a = root.at("authorisations");
    for (std::size_t i = 0; i < a.array().size(); ++i) m.authorisations.insert(a.item(i).str());
  }
  const JsonNode o = root.at("orbits");
  if (o.array().empty()) o.fail("a non-empty array of almanac or RINEX navigation file names");
  m.orbit_files = files(o, base_dir);
}

void readIntegrity(const JsonNode& n, Mission& m) {
  n.requireKnownFields({"method", "fde", "mask_deg", "user_model", "sample_s", "cost_weight", "cost_cell_m"});
  if (n.has("method")) {
    const std::string meth = n.at("method").str();
    if (meth == "raim") m.method = integrity::IntegrityMethod::kRaim;
    else if (meth == "araim") m.method = integrity::IntegrityMethod::kAraim;
    else n.at("method").fail("\"raim\" or \"araim\"");
  }
  if (n.has("fde")) m.with_exclusion = n.at("fde").boolean();
  if (n.has("mask_deg")) m.mask_deg = n.at("mask_deg").number();
  if (n.has("user_model")) {
    const std::string u = n.at("user_model").str();
    if (u == "dual_frequency") m.model.setUserModel(integrity::UserErrorModel::kDualFrequency);
    else if (u == "single_frequency") m.model.setUserModel(integrity::UserErrorModel::kSingleFrequency);
    else n.at("user_model").fail("\"dual_frequency\" or \"single_frequency\"");
  }
  if (n.has("sample_s")) m.sample_s = n.at("sample_s").positiveUpTo(kMaxTimeLimit_s, "s");
  if (n.has("cost_weight")) {
    m.cost_weight = n.at("cost_weight").number();
    if (!(m.cost_weight >= 0.0)) n.at("cost_weight").fail("a weight ≥ 0");
  }
  if (n.has("cost_cell_m")) m.cost_cell_m = n.at("cost_cell_m").positiveUpTo(kMaxPlannerLength_m, "m");
}

/// \brief A declared protection level: a finite number > 0 [m].
double declaredPl(const JsonNode& n) {
  const double v = n.number();
  if (!(std::isfinite(v) && v > 0.0)) n.fail("a protection level in metres > 0");
  return v;
}

/// \brief `navigation`: {"kind": "gnss"}, {"kind": "gnss_ins", "imu": grade} or
/// {"kind": "receiver", "hpl_m": x, "vpl_m": y}; each kind takes only its own fields.
void readNavigation(const JsonNode& n, Mission& m) {
  if (!n.j.is_object()) n.fail("an object with kind \"gnss\", \"gnss_ins\" or \"receiver\"");
  const JsonNode kind = n.at("kind");
  const std::string k = kind.str();
  NavigationModel& nav = m.navigation;
  if (k == "gnss") {
    n.requireKnownFields({"kind"});
    nav.kind = NavigationKind::kGnss;
  } else if (k == "gnss_ins") {
    n.requireKnownFields({"kind", "imu"});
    nav.kind = NavigationKind::kGnssIns;
    const JsonNode imu = n.at("imu");
    const auto grade = integrity::ins::parseImuGrade(imu.str());
    if (!grade) imu.fail("an IMU grade: \"aviation\", \"tactical\" or \"consumer\"");
    nav.imu = *grade;
  } else if (k == "receiver") {
    n.requireKnownFields({"kind", "hpl_m", "vpl_m"});
    nav.kind = NavigationKind::kReceiver;
    nav.hpl_m = declaredPl(n.at("hpl_m"));
    nav.vpl_m = declaredPl(n.at("vpl_m"));
  } else {
    kind.fail("\"gnss\", \"gnss_ins\" or \"receiver\"");
  }
}

/// \brief `policy`: {"min_level1_availability": a fraction in [0, 1]}.
void readPolicy(const JsonNode& p, Mission& m) {
  p.requireKnownFields({"min_level1_availability"});
  if (p.has("min_level1_availability")) {
    const JsonNode a = p.at("min_level1_availability");
    const double v = a.number();
    if (!(v >= 0.0 && v <= 1.0)) a.fail("a fraction of the route's samples in [0, 1] (0.95 for 95 %)");
    m.policy.min_level1_availability = v;
  }
}

void readPlannerSettings(const JsonNode& p, Mission& m) {
  p.requireKnownFields(
      {"algorithm", "time_limit_s", "iterations", "seed", "resolution_m", "simplify", "margin_m", "max_replans",
       "lattice_fallback"});
  if (p.has("algorithm")) {
    const auto k = parsePlannerKind(p.at("algorithm").str());
    if (!k) p.at("algorithm").fail("\"rrtstar\", \"informed_rrtstar\", \"bitstar\", \"prmstar\" or \"lattice\"");
    m.planner = *k;
  }
  if (p.has("time_limit_s")) m.time_limit_s = p.at("time_limit_s").positiveUpTo(kMaxTimeLimit_s, "s");
  if (p.has("iterations")) {
    const double it = p.at("iterations").number();
    if (!(it >= 1 && it <= 1e9 && it == std::floor(it))) p.at("iterations").fail("a whole number 1…10⁹");
    m.iterations = static_cast<std::uint64_t>(it);
  }
  if (p.has("seed")) {
    const double s = p.at("seed").number();
    if (!(s >= 0 && s < 4294967296.0 && s == std::floor(s))) p.at("seed").fail("a whole number 0…2³²−1");
    m.seed = static_cast<std::uint64_t>(s);
  }
  if (p.has("resolution_m")) m.resolution_m = p.at("resolution_m").positiveUpTo(kMaxPlannerLength_m, "m");
  if (p.has("simplify")) m.simplify = p.at("simplify").boolean();
  if (p.has("lattice_fallback")) m.lattice_fallback = p.at("lattice_fallback").boolean();
  if (p.has("margin_m")) m.margin_m = p.at("margin_m").positiveUpTo(kMaxPlannerLength_m, "m");
  if (p.has("max_replans")) {
    const double r = p.at("max_replans").number();
    if (!(r >= 0 && r <= 20 && r == std::floor(r))) p.at("max_replans").fail("a whole number 0…20");
    m.max_replans = static_cast<int>(r);
  }
}

}  // namespace

const char* navigationKindName(NavigationKind kind) {
  switch (kind) {
    case NavigationKind::kGnss: return "gnss";
    case NavigationKind::kGnssIns: return "gnss_ins";
    case NavigationKind::kReceiver: return "receiver";
  }
  return "?";
}

QgcPlanRoute parseQgcPlanRoute(const nlohmann::json& doc, const std::string& source) {
  const JsonNode root{doc, "$", source};
  const JsonNode mission = planMission(root);
  PlanWalk w;
  w.home = plannedHome(mission);
  w.home_path = mission.path + ".plannedHomePosition";
  const JsonNode items = mission.at("items");
  for (std::size_t i = 0; i < items.array().size(); ++i) {
    const JsonNode item = items.item(i);
    if (const std::optional<int> command = routeCommand(item)) addRouteItem(w, item, *command);
  }
  if (w.route.points.size() < 2) {
    items.fail("at least one NAV_WAYPOINT, NAV_LAND with a position or RETURN_TO_LAUNCH away from the start");
  }
  if (w.heights_agree && w.common_height_m) {
    w.route.cruise_agl_m = *w.common_height_m;
  } else {
    w.route.cruise_agl_field.clear();
  }
  w.route.home = w.home ? *w.home : w.route.points.front();
  w.route.has_geofence = hasGeofence(doc);
  return w.route;
}

Mission parseMission(const nlohmann::json& doc, const std::string& source, const std::string& base_dir,
                     const JsonFileReader& read_json) {
  const JsonNode root{doc, "$", source};
  requireMissionFields(root);
  Mission m;
  m.source = source;
  if (root.has("name")) m.name = root.at("name").str();
  readVehicle(root.at("vehicle"), m);
  if (root.has("k1")) m.levels.k1 = root.at("k1").positiveUpTo(kMaxBoxFactor, "(a factor)");
  if (root.has("k2")) m.levels.k2 = root.at("k2").positiveUpTo(kMaxBoxFactor, "(a factor)");
  const std::optional<QgcPlanRoute> plan_route = readRoute(root, base_dir, read_json, m);
  readAltitudes(root, plan_route, m);
  readDeparture(root, m);
  readDataFiles(root, base_dir, m);
  addPlanFence(plan_route, m);
  if (root.has("integrity")) readIntegrity(root.at("integrity"), m);
  if (root.has("navigation")) readNavigation(root.at("navigation"), m);
  if (root.has("policy")) readPolicy(root.at("policy"), m);
  if (root.has("planner")) readPlannerSettings(root.at("planner"), m);
  return m;
}

Mission loadMission(const std::string& path) {
  return parseMission(maps::readJsonFile(path), path, std::filesystem::path(path).parent_path().string());
}

}  // namespace skylane::planner
