#include "planner/tracking/track_fix.hpp"

#include "integrity/ins/protection_levels.hpp"
#include "integrity/ins/imu_grade.hpp"
#include "integrity/stats.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace skylane::planner {

using maps::ParseError;
using nlohmann::json;

const char* plSourceName(PlSource s) {
  switch (s) {
    case PlSource::kOnboard: return "onboard";
    case PlSource::kRaw: return "raw";
    case PlSource::kNmeaGst: return "nmea_gst";
    case PlSource::kIns: return "ins";
    case PlSource::kGnssIns: return "gnss_ins";
    case PlSource::kMavlinkAccuracy: return "mavlink_accuracy";
    case PlSource::kUbxPl: return "ubx_pl";
    case PlSource::kUbxAccuracy: return "ubx_accuracy";
  }
  return "?";
}

std::pair<double, double> insNominalPl(const InsUncertainty& ins) {
  const integrity::ins::ThreeHypothesisInsConfig cfg;
  const double lambda = integrity::ins::imuErrorWeightRatio(ins.grade);
  const double k_h = integrity::normalTailInverse(lambda * cfg.phmi_h * cfg.share[0]);
  const double k_v = integrity::normalTailInverse(lambda * cfg.phmi_v * cfg.share[0]);
  return {k_h * std::hypot(ins.sigma_n_m, ins.sigma_e_m), k_v * ins.sigma_u_m};
}

namespace {

/// \brief The document is one object with only the schema's fields.
void requireFixObject(const maps::JsonNode& root) {
  if (!root.j.is_object()) root.fail("one JSON object per line {\"time\", \"lat\", \"lon\", \"h_ell_m\", …}");
  root.requireKnownFields({"flight", "vehicle", "time", "lat", "lon", "h_ell_m", "hpl_m", "vpl_m", "pseudoranges", "imu",
                          "velocity_enu_mps", "attitude_deg", "baro_h_m", "mag_heading_deg"});
}

/// \brief `flight` or `vehicle` (one of them, a non-empty string or an integer).
void readFlight(const maps::JsonNode& root, TrackFix& f) {
  if (root.has("flight") && root.has("vehicle")) root.at("vehicle").fail("one of \"flight\" and \"vehicle\", not both");
  for (const char* key : {"flight", "vehicle"}) {
    if (!root.has(key)) continue;
    const maps::JsonNode n = root.at(key);
    f.flight = n.j.is_number_integer() ? std::to_string(n.j.get<long long>()) : n.str();
    if (f.flight.empty()) n.fail("a flight or vehicle identifier");
  }
}

/// \brief `time`, `lat`, `lon` and `h_ell_m`.
void readTimeAndPosition(const maps::JsonNode& root, TrackFix& f) {
  const maps::JsonNode time = root.at("time");
  const auto t = maps::parseRfc3339(time.str());
  if (!t) time.fail("an RFC 3339 date-time such as 2026-11-23T14:00:00Z");
  f.time = *t;
  const maps::JsonNode lat = root.at("lat"), lon = root.at("lon");
  if (std::abs(lat.number()) > 90.0) lat.fail("a latitude in [-90, 90] degrees");
  if (std::abs(lon.number()) > 180.0) lon.fail("a longitude in [-180, 180] degrees");
  f.lat_rad = maps::deg2rad(lat.number());
  f.lon_rad = maps::deg2rad(lon.number());
  f.h_ell_m = root.at("h_ell_m").number();
  if (std::abs(f.h_ell_m) > 1e5) root.at("h_ell_m").fail("an ellipsoidal height within ±100 km");
}

/// \brief The onboard `hpl_m` and `vpl_m`: both or neither.
void readOnboardPls(const maps::JsonNode& root, TrackFix& f) {
  if (root.has("hpl_m") != root.has("vpl_m")) {
    root.orNull(root.has("hpl_m") ? "vpl_m" : "hpl_m").fail("both hpl_m and vpl_m, or neither");
  }
  if (root.has("hpl_m")) {
    for (const char* key : {"hpl_m", "vpl_m"}) {
      const maps::JsonNode n = root.at(key);
      if (n.number() < 0.0) n.fail("a protection level ≥ 0 m");
    }
    f.hpl_m = root.at("hpl_m").number();
    f.vpl_m = root.at("vpl_m").number();
  }
}

/// \brief One element of `pseudoranges`; its satellite must not be among `earlier`.
integrity::RawRange readPseudorange(const maps::JsonNode& r, const std::vector<integrity::RawRange>& earlier) {
  r.requireKnownFields({"sat", "pr_m", "ecef_m"});
  integrity::RawRange raw;
  const maps::JsonNode sat = r.at("sat");
  const auto id = integrity::parseSatId(sat.str());
  if (!id) sat.fail("a satellite such as G05 or E11");
  raw.sat = *id;
  for (const integrity::RawRange& e : earlier) {
    if (e.sat == raw.sat) sat.fail("each satellite once");
  }
  raw.pr_m = r.at("pr_m").number();
  if (!(raw.pr_m > 1e6 && raw.pr_m < 1e8)) r.at("pr_m").fail("a pseudorange between 1,000 and 100,000 km");
  if (r.has("ecef_m")) {
    const maps::JsonNode e = r.at("ecef_m");
    if (e.array().size() != 3) e.fail("[x, y, z] in metres");
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p[k] = e.item(static_cast<std::size_t>(k)).number();
    if (!(p.norm() > 1e7 && p.norm() < 1e8)) e.fail("a satellite position 10,000–100,000 km from the Earth's centre");
    raw.sat_ecef_m = p;
  }
  return raw;
}

/// \brief `pseudoranges`, when given.
void readPseudoranges(const maps::JsonNode& root, TrackFix& f) {
  if (!root.has("pseudoranges")) return;
  const maps::JsonNode list = root.at("pseudoranges");
  for (std::size_t i = 0; i < list.array().size(); ++i) f.ranges.push_back(readPseudorange(list.item(i), f.ranges));
}

/// \brief One row of `imu.increments`: [dt_s, dθx, dθy, dθz, dvx, dvy, dvz].
ImuIncrement readImuIncrement(const maps::JsonNode& row) {
  if (row.array().size() != 7) row.fail("[dt_s, dθx, dθy, dθz (rad), dvx, dvy, dvz (m/s)]");
  double v[7];
  for (std::size_t k = 0; k < 7; ++k) v[k] = row.item(k).number();
  ImuIncrement inc;
  inc.dt_s = v[0];
  if (!(inc.dt_s > 0.0 && inc.dt_s <= 1.0)) row.item(0).fail("an interval in (0, 1] s");
  inc.dtheta_rad = Eigen::Vector3d(v[1], v[2], v[3]);
  inc.dv_mps = Eigen::Vector3d(v[4], v[5], v[6]);
  // Bounds: 2000 °/s and 50 g over the interval, far beyond any airframe's.
  if (inc.dtheta_rad.norm() > 35.0 * inc.dt_s) row.fail("an angle increment below 35 rad/s × dt_s");
  if (inc.dv_mps.norm() > 500.0 * inc.dt_s) row.fail("a velocity increment below 500 m/s² × dt_s");
  return inc;
}

/// \brief `imu.increments` (and no INS σ's beside them).
ImuRecord readImuIncrements(const maps::JsonNode& imu, int grade) {
  for (const char* key : {"sigma_n_m", "sigma_e_m", "sigma_u_m"}) {
    if (imu.has(key)) imu.at(key).fail("either the INS σ's or the IMU increments, not both");
  }
  ImuRecord rec;
  rec.grade = grade;
  const maps::JsonNode list = imu.at("increments");
  const std::size_t n = list.array().size();
  if (n == 0 || n > 10000) list.fail("1 to 10,000 increments [dt_s, dθx, dθy, dθz, dvx, dvy, dvz]");
  rec.increments.reserve(n);
  for (std::size_t i = 0; i < n; ++i) rec.increments.push_back(readImuIncrement(list.item(i)));
  if (rec.span_s() > 60.0) list.fail("increments spanning at most 60 s");
  return rec;
}

/// \brief The INS σ's `imu.sigma_n_m`, `sigma_e_m` and `sigma_u_m`.
InsUncertainty readInsSigmas(const maps::JsonNode& imu, int grade) {
  InsUncertainty u;
  u.grade = grade;
  for (auto [key, dst] : {std::pair{"sigma_n_m", &u.sigma_n_m}, {"sigma_e_m", &u.sigma_e_m}, {"sigma_u_m", &u.sigma_u_m}}) {
    const maps::JsonNode n = imu.at(key);
    if (n.number() < 0.0) n.fail("a standard deviation ≥ 0 m");
    *dst = n.number();
  }
  return u;
}

/// \brief The `imu` block, when given: its grade and either the increments or the INS σ's.
void readImu(const maps::JsonNode& root, TrackFix& f) {
  if (!root.has("imu")) return;
  const maps::JsonNode imu = root.at("imu");
  imu.requireKnownFields({"grade", "sigma_n_m", "sigma_e_m", "sigma_u_m", "increments"});
  const auto parsed = integrity::ins::parseImuGrade(imu.at("grade").str());
  if (!parsed) imu.at("grade").fail("aviation, tactical or consumer (the IMU grades of docs/method.md §5.1)");
  const int grade = static_cast<int>(*parsed);
  if (imu.has("increments")) {
    f.imu = readImuIncrements(imu, grade);
  } else {
    f.ins = readInsSigmas(imu, grade);
  }
}

/// \brief The onboard navigation that aligns and aids the filter: `velocity_enu_mps`,
/// `attitude_deg`, `baro_h_m` and `mag_heading_deg`, each when given.
void readNavigationAids(const maps::JsonNode& root, TrackFix& f) {
  if (root.has("velocity_enu_mps")) {
    const maps::JsonNode v = root.at("velocity_enu_mps");
    if (v.array().size() != 3) v.fail("[ve, vn, vu] in m/s");
    Eigen::Vector3d vel;
    for (int k = 0; k < 3; ++k) vel[k] = v.item(static_cast<std::size_t>(k)).number();
    if (vel.norm() > 400.0) v.fail("a velocity below 400 m/s");
    f.velocity_enu_mps = vel;
  }
  if (root.has("attitude_deg")) {
    const maps::JsonNode a = root.at("attitude_deg");
    a.requireKnownFields({"roll", "pitch", "heading"});
    const double roll = a.at("roll").number(), pitch = a.at("pitch").number(), heading = a.at("heading").number();
    if (std::abs(roll) > 180.0) a.at("roll").fail("a roll in [-180, 180] degrees");
    if (std::abs(pitch) > 90.0) a.at("pitch").fail("a pitch in [-90, 90] degrees");
    if (heading < -360.0 || heading > 360.0) a.at("heading").fail("a heading in [-360, 360] degrees");
    f.attitude_rad = Eigen::Vector3d(maps::deg2rad(roll), maps::deg2rad(pitch), maps::deg2rad(heading));
  }
  if (root.has("baro_h_m")) {
    const maps::JsonNode b = root.at("baro_h_m");
    if (std::abs(b.number()) > 1e5) b.fail("a barometric height within ±100 km");
    f.baro_h_m = b.number();
  }
  if (root.has("mag_heading_deg")) {
    const maps::JsonNode m = root.at("mag_heading_deg");
    if (m.number() < -360.0 || m.number() > 360.0) m.fail("a heading in [-360, 360] degrees");
    f.mag_heading_rad = maps::deg2rad(m.number());
  }
}

/// \brief A fix needs a protection level: onboard PLs, pseudoranges or the INS σ's; IMU
/// increments need pseudoranges or onboard PLs beside them.
void requireProtectionLevelSource(const maps::JsonNode& root, const TrackFix& f) {
  if (f.imu && f.ranges.empty() && !f.hpl_m) {
    root.at("imu").fail("pseudoranges with the IMU increments (GNSS/INS), or hpl_m and vpl_m");
  }
  if (!f.hpl_m && f.ranges.empty() && !f.ins) {
    root.fail("a protection level: hpl_m and vpl_m, pseudoranges, or an imu block");
  }
}

}  // namespace

TrackFix parseTrackFixJson(const json& doc, const std::string& source) {
  const maps::JsonNode root{doc, "$", source};
  requireFixObject(root);
  TrackFix f;
  f.source = source;
  readFlight(root, f);
  readTimeAndPosition(root, f);
  readOnboardPls(root, f);
  readPseudoranges(root, f);
  readImu(root, f);
  readNavigationAids(root, f);
  requireProtectionLevelSource(root, f);
  if (!f.ranges.empty()) f.pl_source = PlSource::kRaw;
  return f;
}

TrackFix trackFixFromNmea(const integrity::NmeaFix& fix, const std::string& source, const NmeaPlRisk& risk) {
  if (fix.quality == 0) throw ParseError(source, 0, "GGA field 6 (quality)", "0", "a position fix (quality ≥ 1)");
  if (!fix.gst) throw ParseError(source, 0, "GST", "", "a GST sentence for this epoch (the error statistics the PLs come from)");
  const integrity::NmeaGst& g = *fix.gst;
  double sigma_h = g.semi_major_m.value_or(0.0);
  if (!(sigma_h > 0.0)) sigma_h = std::max(g.sigma_lat_m.value_or(0.0), g.sigma_lon_m.value_or(0.0));
  double sigma_v = g.sigma_alt_m.value_or(-1.0);
  if (!(sigma_h > 0.0)) throw ParseError(source, 0, "GST fields 3, 6–7", "", "a horizontal error σ (semi-major axis or latitude/longitude σ)");
  if (sigma_v < 0.0) throw ParseError(source, 0, "GST field 8 (altitude σ)", "", "a vertical error σ");
  if (fix.gbs) {
    const integrity::NmeaGbs& b = *fix.gbs;
    sigma_h = std::max(sigma_h, std::max(b.err_lat_m.value_or(0.0), b.err_lon_m.value_or(0.0)));
    sigma_v = std::max(sigma_v, b.err_alt_m.value_or(0.0));
  }
  TrackFix f;
  f.source = source;
  f.time = fix.time;
  f.lat_rad = fix.lat_rad;
  f.lon_rad = fix.lon_rad;
  f.h_ell_m = fix.h_ell_m;
  f.hpl_m = std::sqrt(-2.0 * std::log(risk.p_h)) * sigma_h;
  f.vpl_m = integrity::normalTailInverse(risk.p_v / 2.0) * sigma_v;
  f.pl_source = PlSource::kNmeaGst;
  return f;
}

namespace {

double round_to(double v, double step) { return std::round(v / step) * step; }

json vec(const Eigen::Vector3d& v, double step) {
  return json::array({round_to(v.x(), step), round_to(v.y(), step), round_to(v.z(), step)});
}

}  // namespace

json trackFixJson(const TrackFix& f) {
  json j;
  if (!f.flight.empty()) j["flight"] = f.flight;
  j["time"] = maps::formatRfc3339(f.time, 3);
  j["lat"] = round_to(maps::rad2deg(f.lat_rad), 1e-9);
  j["lon"] = round_to(maps::rad2deg(f.lon_rad), 1e-9);
  j["h_ell_m"] = round_to(f.h_ell_m, 1e-4);
  if (f.hpl_m && f.vpl_m) {
    j["hpl_m"] = round_to(*f.hpl_m, 1e-4);
    j["vpl_m"] = round_to(*f.vpl_m, 1e-4);
  }
  if (!f.ranges.empty()) {
    json list = json::array();
    for (const integrity::RawRange& r : f.ranges) {
      json one = {{"sat", r.sat.str()}, {"pr_m", round_to(r.pr_m, 1e-4)}};
      if (r.sat_ecef_m) one["ecef_m"] = vec(*r.sat_ecef_m, 1e-4);
      list.push_back(std::move(one));
    }
    j["pseudoranges"] = std::move(list);
  }
  auto grade = [](int g) { return std::string(integrity::ins::imuGradeName(static_cast<integrity::ins::ImuGrade>(g))); };
  if (f.imu) {
    json inc = json::array();
    for (const ImuIncrement& i : f.imu->increments) {
      inc.push_back({i.dt_s, i.dtheta_rad.x(), i.dtheta_rad.y(), i.dtheta_rad.z(), i.dv_mps.x(), i.dv_mps.y(), i.dv_mps.z()});
    }
    j["imu"] = {{"grade", grade(f.imu->grade)}, {"increments", std::move(inc)}};
  } else if (f.ins) {
    j["imu"] = {{"grade", grade(f.ins->grade)}, {"sigma_n_m", f.ins->sigma_n_m}, {"sigma_e_m", f.ins->sigma_e_m}, {"sigma_u_m", f.ins->sigma_u_m}};
  }
  if (f.velocity_enu_mps) j["velocity_enu_mps"] = vec(*f.velocity_enu_mps, 1e-4);
  if (f.attitude_rad) {
    j["attitude_deg"] = {{"roll", round_to(maps::rad2deg(f.attitude_rad->x()), 1e-6)},
                         {"pitch", round_to(maps::rad2deg(f.attitude_rad->y()), 1e-6)},
                         {"heading", round_to(maps::rad2deg(f.attitude_rad->z()), 1e-6)}};
  }
  if (f.baro_h_m) j["baro_h_m"] = round_to(*f.baro_h_m, 1e-4);
  if (f.mag_heading_rad) j["mag_heading_deg"] = round_to(maps::rad2deg(*f.mag_heading_rad), 1e-6);
  return j;
}

}  // namespace skylane::planner
