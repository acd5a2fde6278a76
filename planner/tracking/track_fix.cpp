#include "planner/tracking/track_fix.hpp"

#include "integrity/ins/protection_levels.hpp"
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
  }
  return "?";
}

std::pair<double, double> insNominalPl(const InsUncertainty& ins) {
  const integrity::ins::Seed000Config cfg;
  const double lambda = integrity::ins::seed000Lambda(ins.grade);
  const double k_h = integrity::normalTailInverse(lambda * cfg.phmi_h * cfg.share[0]);
  const double k_v = integrity::normalTailInverse(lambda * cfg.phmi_v * cfg.share[0]);
  return {k_h * std::hypot(ins.sigma_n_m, ins.sigma_e_m), k_v * ins.sigma_u_m};
}

TrackFix parseTrackFixJson(const json& doc, const std::string& source) {
  const maps::JsonNode root{doc, "$", source};
  if (!doc.is_object()) root.fail("one JSON object per line {\"time\", \"lat\", \"lon\", \"h_ell_m\", …}");
  root.requireKnownFields({"flight", "vehicle", "time", "lat", "lon", "h_ell_m", "hpl_m", "vpl_m", "pseudoranges", "imu"});
  TrackFix f;
  f.source = source;
  if (root.has("flight") && root.has("vehicle")) root.at("vehicle").fail("one of \"flight\" and \"vehicle\", not both");
  for (const char* key : {"flight", "vehicle"}) {
    if (!root.has(key)) continue;
    const maps::JsonNode n = root.at(key);
    f.flight = n.j.is_number_integer() ? std::to_string(n.j.get<long long>()) : n.str();
    if (f.flight.empty()) n.fail("a flight or vehicle identifier");
  }
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
  if (root.has("pseudoranges")) {
    const maps::JsonNode list = root.at("pseudoranges");
    for (std::size_t i = 0; i < list.array().size(); ++i) {
      const maps::JsonNode r = list.item(i);
      r.requireKnownFields({"sat", "pr_m", "ecef_m"});
      integrity::RawRange raw;
      const maps::JsonNode sat = r.at("sat");
      const auto id = integrity::parseSatId(sat.str());
      if (!id) sat.fail("a satellite such as G05 or E11");
      raw.sat = *id;
      for (const integrity::RawRange& e : f.ranges) {
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
      f.ranges.push_back(raw);
    }
  }
  if (root.has("imu")) {
    const maps::JsonNode imu = root.at("imu");
    imu.requireKnownFields({"grade", "sigma_n_m", "sigma_e_m", "sigma_u_m"});
    InsUncertainty u;
    const std::string grade = imu.at("grade").str();
    if (grade == "aviation") u.grade = 0;
    else if (grade == "tactical") u.grade = 1;
    else if (grade == "consumer") u.grade = 2;
    else imu.at("grade").fail("aviation, tactical or consumer (seed 000 Table 1)");
    for (auto [key, dst] : {std::pair{"sigma_n_m", &u.sigma_n_m}, {"sigma_e_m", &u.sigma_e_m}, {"sigma_u_m", &u.sigma_u_m}}) {
      const maps::JsonNode n = imu.at(key);
      if (n.number() < 0.0) n.fail("a standard deviation ≥ 0 m");
      *dst = n.number();
    }
    f.ins = u;
  }
  if (!f.hpl_m && f.ranges.empty() && !f.ins) {
    root.fail("a protection level: hpl_m and vpl_m, pseudoranges, or an imu block");
  }
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

}  // namespace skylane::planner
