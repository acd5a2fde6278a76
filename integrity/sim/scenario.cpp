#include "integrity/sim/scenario.hpp"

#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace skylane::integrity::sim {

using maps::JsonNode;

namespace {

// Bounds of a simulated flight, checked where the scenario is read so that no number sends a
// loop, the local frame or the clock out of range (a rate of 1e9 Hz ran for hours; a spacing
// of 1e99 m put the vehicle at an infinite ECEF position).
constexpr double kMaxImuRate_hz = 2000.0;      ///< the fastest tactical and MEMS IMUs give 1–2 kHz
constexpr double kMaxGnssRate_hz = 20.0;       ///< receivers' fastest navigation rates (10–20 Hz)
constexpr double kMaxFlight_s = 86400.0;       ///< one day: the flight, and every fault's times
constexpr double kMaxImuSamples = 2e7;         ///< IMU samples of one run: about a minute of work
constexpr double kMaxExtent_m = 100e3;         ///< reach of the trajectory in its local ENU frame
constexpr double kMinHeight_m = -1000.0;       ///< heights: Dead Sea shore to above any UAS
constexpr double kMaxHeight_m = 20000.0;
constexpr double kMaxSpeed_mps = 300.0;        ///< below the speed of sound: any UAS
constexpr double kMaxSatBias_m = 1e5;          ///< a pseudorange step of 100 km (a broken clock)
constexpr double kMaxSatBias_sigma = 1e4;      ///< in sigmas of the satellite's error model
constexpr double kMaxAccelBias_mps2 = 1000.0;  ///< 100 g: beyond any IMU's measuring range
constexpr double kMaxGyroBias_radps = 100.0;   ///< 5700 °/s: beyond any IMU's measuring range

double within(const JsonNode& n, double lo, double hi, const std::string& unit) { return n.numberIn(lo, hi, unit); }

double positiveUpTo(const JsonNode& n, double hi, const std::string& unit) { return n.positiveUpTo(hi, unit); }

int axisOf(const JsonNode& n) {
  const std::string a = n.str();
  if (a == "forward" || a == "x") return 0;
  if (a == "left" || a == "y") return 1;
  if (a == "up" || a == "z") return 2;
  n.fail("a body axis: \"forward\"/\"x\", \"left\"/\"y\" or \"up\"/\"z\"");
}

}  // namespace

FaultSpec parseFault(const JsonNode& f) {
  f.requireKnownFields({"type", "sats", "axis", "start_s", "end_s", "ramp", "bias_m", "bias_sigma", "bias_mps2",
                        "bias_g", "bias_radps", "bias_dps"});
  FaultSpec out;
  const JsonNode type = f.at("type");
  const std::string t = type.str();
  out.t_start_s = within(f.at("start_s"), 0.0, kMaxFlight_s, "s");
  out.t_end_s = within(f.at("end_s"), 0.0, kMaxFlight_s, "s");
  if (!(out.t_end_s > out.t_start_s)) f.at("end_s").fail("a time after start_s");
  if (f.has("ramp")) out.ramp = f.at("ramp").boolean();
  auto one = [&f](std::initializer_list<const char*> keys) -> JsonNode {
    for (const char* k : keys) {
      if (f.has(k)) return f.at(k);
    }
    std::string list;
    for (const char* k : keys) list += (list.empty() ? "" : " or ") + std::string(k);
    f.fail("an object with " + list);
  };
  if (t == "satellite") {
    out.target = FaultTarget::kSatellite;
    const JsonNode sats = f.at("sats");
    if (sats.array().empty()) sats.fail("a non-empty array of satellite ids such as \"G19\"");
    for (std::size_t i = 0; i < sats.j.size(); ++i) {
      const JsonNode s = sats.item(i);
      const auto id = parseSatId(s.str());
      if (!id) s.fail("a satellite id such as \"G19\" or \"E11\"");
      out.sats.push_back(*id);
    }
    const JsonNode m = one({"bias_m", "bias_sigma"});
    out.in_sigma = f.has("bias_sigma");
    out.magnitude = out.in_sigma ? within(m, -kMaxSatBias_sigma, kMaxSatBias_sigma, "sigma")
                                 : within(m, -kMaxSatBias_m, kMaxSatBias_m, "m");
  } else if (t == "accelerometer") {
    out.target = FaultTarget::kAccelerometer;
    out.axis = axisOf(f.at("axis"));
    const JsonNode m = one({"bias_mps2", "bias_g"});
    const double unit = f.has("bias_g") ? 9.80665 : 1.0;
    out.magnitude = within(m, -kMaxAccelBias_mps2 / unit, kMaxAccelBias_mps2 / unit, f.has("bias_g") ? "g" : "m/s²") * unit;
  } else if (t == "gyro") {
    out.target = FaultTarget::kGyro;
    out.axis = axisOf(f.at("axis"));
    const JsonNode m = one({"bias_radps", "bias_dps"});
    const double unit = f.has("bias_dps") ? M_PI / 180.0 : 1.0;
    out.magnitude = within(m, -kMaxGyroBias_radps / unit, kMaxGyroBias_radps / unit, f.has("bias_dps") ? "°/s" : "rad/s") * unit;
  } else if (t == "outage") {
    out.target = FaultTarget::kGnssOutage;
    out.magnitude = 1.0;
    out.ramp = false;
  } else {
    type.fail("\"satellite\", \"accelerometer\", \"gyro\" or \"outage\"");
  }
  return out;
}

void matchFilterToSensors(ins::NavigatorConfig& nav, const SensorSpec& sensors, ImuGrade grade) {
  ins::tuneFilterToSensors(nav, sensors, grade);
  nav.model = sensors.model;
  nav.elevation_mask_rad = sensors.elevation_mask_rad;
}

void matchFilterToSensors(Scenario& s) {
  matchFilterToSensors(s.navigator, s.sensors, s.grade);
  s.navigator.araim.requirements.hal_m = s.hal_m;
  s.navigator.araim.requirements.val_m = s.val_m;
}

namespace {

/// \brief `origin`: latitude within ±89°, longitude within ±180°, ellipsoidal height.
void readOrigin(const JsonNode& root, Scenario& s) {
  const JsonNode o = root.at("origin");
  o.requireKnownFields({"lat_deg", "lon_deg", "h_ell_m"});
  const double lat = o.at("lat_deg").number(), lon = o.at("lon_deg").number();
  if (std::abs(lat) > 89.0) o.at("lat_deg").fail("a latitude within ±89°");
  if (std::abs(lon) > 180.0) o.at("lon_deg").fail("a longitude within ±180°");
  s.origin = {maps::deg2rad(lat), maps::deg2rad(lon), within(o.at("h_ell_m"), kMinHeight_m, kMaxHeight_m, "m")};
}

/// \brief `start`: an RFC 3339 UTC time.
void readStart(const JsonNode& root, Scenario& s) {
  const JsonNode t = root.at("start");
  const auto parsed = maps::parseRfc3339(t.str());
  if (!parsed) t.fail("an RFC 3339 UTC time such as \"2020-01-01T10:00:00Z\"");
  s.start = *parsed;
}

/// \brief `orbits`: file names, relative ones resolved against `base_dir`.
void readOrbits(const JsonNode& root, const std::string& base_dir, Scenario& s) {
  const JsonNode o = root.at("orbits");
  if (o.array().empty()) o.fail("a non-empty array of almanac or RINEX navigation file names");
  for (std::size_t i = 0; i < o.j.size(); ++i) {
    std::filesystem::path p(o.item(i).str());
    if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
    s.orbit_files.push_back(p.lexically_normal().string());
  }
}

/// \brief `trajectory.lawnmower`: the lines' waypoints.
std::vector<Waypoint> readLawnmower(const JsonNode& l) {
  l.requireKnownFields({"lines", "line_length_m", "spacing_m", "height_m", "speed_mps", "heading_deg"});
  const double lines = l.at("lines").number();
  if (!(lines >= 1 && lines <= 1000 && lines == std::floor(lines))) l.at("lines").fail("a whole number 1…1000");
  // The lines side by side span (lines − 1) × spacing: within the frame's reach too.
  const double spacing_m = positiveUpTo(l.at("spacing_m"), kMaxExtent_m / std::max(1.0, lines - 1.0), "m (lines × spacing within 100 km)");
  return lawnmower(static_cast<int>(lines), positiveUpTo(l.at("line_length_m"), kMaxExtent_m, "m"), spacing_m,
                   within(l.at("height_m"), kMinHeight_m, kMaxHeight_m, "m"), positiveUpTo(l.at("speed_mps"), kMaxSpeed_mps, "m/s"),
                   l.has("heading_deg") ? maps::deg2rad(within(l.at("heading_deg"), -360.0, 360.0, "°")) : 0.0);
}

/// \brief `trajectory.waypoints`: at least 2; the first one's speed defaults to 1 m/s.
std::vector<Waypoint> readWaypoints(const JsonNode& w) {
  std::vector<Waypoint> out;
  if (w.array().size() < 2) w.fail("an array of at least 2 waypoints");
  for (std::size_t i = 0; i < w.j.size(); ++i) {
    const JsonNode p = w.item(i);
    p.requireKnownFields({"e_m", "n_m", "u_m", "speed_mps"});
    Waypoint wp;
    wp.p_enu_m = {within(p.at("e_m"), -kMaxExtent_m, kMaxExtent_m, "m"), within(p.at("n_m"), -kMaxExtent_m, kMaxExtent_m, "m"),
                  within(p.at("u_m"), kMinHeight_m, kMaxHeight_m, "m")};
    wp.speed_mps = i == 0 && !p.has("speed_mps") ? 1.0 : positiveUpTo(p.at("speed_mps"), kMaxSpeed_mps, "m/s");
    out.push_back(wp);
  }
  return out;
}

/// \brief `trajectory`: the turn radius and exactly one of a lawnmower or waypoints.
void readTrajectory(const JsonNode& root, Scenario& s) {
  const JsonNode t = root.at("trajectory");
  t.requireKnownFields({"lawnmower", "waypoints", "turn_radius_m"});
  if (t.has("turn_radius_m")) s.turn_radius_m = positiveUpTo(t.at("turn_radius_m"), kMaxExtent_m, "m");
  if (t.has("lawnmower") == t.has("waypoints")) t.fail("an object with exactly one of lawnmower or waypoints");
  if (t.has("lawnmower")) {
    s.waypoints = readLawnmower(t.at("lawnmower"));
  } else {
    s.waypoints = readWaypoints(t.at("waypoints"));
  }
}

/// \brief `imu`, when given: the grade (and its error figures) and the rate.
void readImu(const JsonNode& root, Scenario& s) {
  if (!root.has("imu")) return;
  const JsonNode i = root.at("imu");
  i.requireKnownFields({"grade", "rate_hz"});
  if (i.has("grade")) {
    const auto g = parseImuGrade(i.at("grade").str());
    if (!g) i.at("grade").fail("\"aviation\", \"tactical\" or \"consumer\"");
    s.grade = *g;
  }
  s.sensors.imu = imuSpec(s.grade);
  if (i.has("rate_hz")) s.sensors.imu.rate_hz = positiveUpTo(i.at("rate_hz"), kMaxImuRate_hz, "Hz");
}

/// \brief `gnss`, when given: rate, elevation mask and user error model.
void readGnss(const JsonNode& root, Scenario& s) {
  if (!root.has("gnss")) return;
  const JsonNode g = root.at("gnss");
  g.requireKnownFields({"rate_hz", "elevation_mask_deg", "user_model"});
  if (g.has("rate_hz")) s.sensors.gnss_rate_hz = positiveUpTo(g.at("rate_hz"), kMaxGnssRate_hz, "Hz");
  if (g.has("elevation_mask_deg")) s.sensors.elevation_mask_rad = maps::deg2rad(within(g.at("elevation_mask_deg"), 0.0, 89.0, "°"));
  if (g.has("user_model")) {
    const std::string m = g.at("user_model").str();
    if (m == "dual_frequency") s.sensors.model.setUserModel(UserErrorModel::kDualFrequency);
    else if (m == "single_frequency") s.sensors.model.setUserModel(UserErrorModel::kSingleFrequency);
    else g.at("user_model").fail("\"dual_frequency\" or \"single_frequency\"");
  }
}

/// \brief `baro` and `magnetometer`, when given: whether the filter uses them.
void readAidingSwitches(const JsonNode& root, Scenario& s) {
  if (root.has("baro")) s.navigator.use_baro = root.at("baro").boolean();
  if (root.has("magnetometer")) s.navigator.use_heading = root.at("magnetometer").boolean();
}

/// \brief `faults`, when given: each one by parseFault.
void readFaults(const JsonNode& root, Scenario& s) {
  if (!root.has("faults")) return;
  const JsonNode f = root.at("faults");
  for (std::size_t i = 0; i < f.array().size(); ++i) s.faults.push_back(parseFault(f.item(i)));
}

/// \brief A probability in (0, 1).
double probability(const JsonNode& p) {
  const double v = p.number();
  if (!(v > 0.0 && v < 1.0)) p.fail("a probability in (0, 1)");
  return v;
}

/// \brief `integrity`, when given: alert limits, risks, false-alert probabilities, ARAIM on/off.
void readIntegrity(const JsonNode& root, Scenario& s) {
  if (!root.has("integrity")) return;
  const JsonNode n = root.at("integrity");
  n.requireKnownFields({"hal_m", "val_m", "i_req", "p_sat", "p_imu", "pfa_gnss", "pfa_imu", "araim"});
  if (n.has("hal_m")) s.hal_m = positiveUpTo(n.at("hal_m"), kMaxExtent_m, "m");
  if (n.has("val_m")) s.val_m = positiveUpTo(n.at("val_m"), kMaxExtent_m, "m");
  if (n.has("i_req")) s.navigator.fault_modes.risk.i_req = probability(n.at("i_req"));
  if (n.has("p_sat")) s.navigator.fault_modes.risk.p_sat = probability(n.at("p_sat"));
  if (n.has("p_imu")) s.navigator.fault_modes.risk.p_imu = probability(n.at("p_imu"));
  if (n.has("pfa_gnss")) s.navigator.fault_modes.pfa_gnss = probability(n.at("pfa_gnss"));
  if (n.has("pfa_imu")) s.navigator.pfa_imu = probability(n.at("pfa_imu"));
  if (n.has("araim")) s.navigator.compute_araim = n.at("araim").boolean();
}

/// \brief `seed`, when given: a whole number ≥ 0 that a double holds exactly.
void readSeed(const JsonNode& root, Scenario& s) {
  if (!root.has("seed")) return;
  const JsonNode sd = root.at("seed");
  const double v = sd.number();
  if (!(v >= 0 && v < 9.007199254740992e15 && v == std::floor(v))) sd.fail("a whole number ≥ 0");
  s.seed = static_cast<std::uint64_t>(v);
}

/// \brief The trajectory builds, lasts at most kMaxFlight_s, and the IMU rate is a whole multiple
/// of the GNSS rate giving at most kMaxImuSamples; checked here so that a bad one is reported
/// against this file and its field.
void requireFlyableTrajectory(const JsonNode& root, const Scenario& s) {
  double duration_s = 0.0;
  try {
    duration_s = Trajectory(s.origin, s.waypoints, s.turn_radius_m).duration_s();
  } catch (const std::invalid_argument& e) {
    root.at("trajectory").fail(std::string("a flyable trajectory (") + e.what() + ")");
  }
  char what[160];
  if (!(duration_s <= kMaxFlight_s)) {
    std::snprintf(what, sizeof what, "a flight of at most %g s (this one takes %.6g s)", kMaxFlight_s, duration_s);
    root.at("trajectory").fail(what);
  }
  // Only a rate the file gives can be wrong: the defaults (100 Hz, 1 Hz) fit.
  const double imu_hz = s.sensors.imu.rate_hz, ratio = imu_hz / s.sensors.gnss_rate_hz;
  const bool imu_given = root.has("imu") && root.at("imu").has("rate_hz");
  if (!(ratio >= 1.0 && std::abs(ratio - std::round(ratio)) <= 1e-9 * ratio)) {
    std::snprintf(what, sizeof what, "an IMU rate (%g Hz) that is a whole multiple of the GNSS rate (%g Hz)", imu_hz,
                  s.sensors.gnss_rate_hz);
    (imu_given ? root.at("imu").at("rate_hz") : root.at("gnss").at("rate_hz")).fail(what);
  }
  if (imu_given && !(duration_s * imu_hz <= kMaxImuSamples)) {
    std::snprintf(what, sizeof what, "a rate giving at most %g IMU samples over the %.6g s flight", kMaxImuSamples, duration_s);
    root.at("imu").at("rate_hz").fail(what);
  }
}

}  // namespace

Scenario parseScenario(const nlohmann::json& doc, const std::string& source, const std::string& base_dir) {
  const JsonNode root{doc, "$", source};
  root.requireKnownFields({"origin", "start", "orbits", "trajectory", "imu", "gnss", "baro", "magnetometer", "faults",
                           "integrity", "seed"});
  Scenario s;
  s.source = source;
  readOrigin(root, s);
  readStart(root, s);
  readOrbits(root, base_dir, s);
  readTrajectory(root, s);
  readImu(root, s);
  readGnss(root, s);
  readAidingSwitches(root, s);
  readFaults(root, s);
  readIntegrity(root, s);
  readSeed(root, s);
  requireFlyableTrajectory(root, s);
  matchFilterToSensors(s);
  return s;
}

Scenario loadScenario(const std::string& path) {
  const std::filesystem::path p(path);
  return parseScenario(maps::readJsonFile(path), path, p.parent_path().string());
}

}  // namespace skylane::integrity::sim
