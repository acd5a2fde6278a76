#include "integrity/geometry_file.hpp"

#include "maps/text_file.hpp"

#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/atmosphere.hpp"
#include "integrity/gnss/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <set>

namespace skylane::integrity {
namespace {

using nlohmann::json;

std::string shown(const json& v) {
  // Structured values are described, not dumped: dump() recurses and a hostile nesting depth
  // would overflow the stack.
  if (v.is_object()) return "an object";
  if (v.is_array()) return "an array of " + std::to_string(v.size());
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

void requireKeys(const json& obj, const std::set<std::string>& allowed, const std::string& src, const std::string& path) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (!allowed.count(it.key())) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw ParseError(src, 0, path.empty() ? it.key() : path + "." + it.key(), "(unknown field)", "one of: " + list);
    }
  }
}

double number(const json& obj, const std::string& key, double def, const std::string& src, const std::string& path,
              double lo, double hi, const char* expected) {
  const auto it = obj.find(key);
  if (it == obj.end()) return def;
  const std::string where = path.empty() ? key : path + "." + key;
  if (!it->is_number()) throw ParseError(src, 0, where, shown(*it), expected);
  const double v = it->get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) throw ParseError(src, 0, where, shown(*it), expected);
  return v;
}

/// Integrity probabilities below this are not meaningful (and halving them must stay normal).
constexpr double kMinProbability = 1e-15;

double probability(const json& obj, const std::string& key, double def, const std::string& src, const std::string& path) {
  const char* expected = "a probability in [1e-15, 1)";
  const double v = number(obj, key, def, src, path, 0.0, 1.0, expected);
  if (!(v >= kMinProbability && v < 1.0)) throw ParseError(src, 0, path + "." + key, shown(obj.at(key)), expected);
  return v;
}

UserErrorModel userModel(const json& v, const std::string& src, const std::string& path) {
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s == "dual_frequency") return UserErrorModel::kDualFrequency;
    if (s == "single_frequency") return UserErrorModel::kSingleFrequency;
  }
  throw ParseError(src, 0, path, shown(v), "\"dual_frequency\" or \"single_frequency\"");
}

}  // namespace

void parseIsm(const json& ism, ErrorModel& model, const std::string& src, const std::string& path) {
  if (!ism.is_object()) throw ParseError(src, 0, path, shown(ism), "an object keyed by constellation (\"GPS\", \"Galileo\", …)");
  for (auto it = ism.begin(); it != ism.end(); ++it) {
    const auto c = constellationFromName(it.key());
    const std::string p = path + "." + it.key();
    if (!c) throw ParseError(src, 0, p, it.key(), "a constellation name: GPS, Galileo, GLONASS or BeiDou");
    if (!it->is_object()) throw ParseError(src, 0, p, shown(*it), "an object with ura_m, ure_m, bnom_m, psat, pconst");
    requireKeys(*it, {"ura_m", "ure_m", "bnom_m", "psat", "pconst"}, src, p);
    IsmEntry& e = model.of(*c);
    e.ura_m = number(*it, "ura_m", e.ura_m, src, p, 1e-3, 1e4, "a σ_URA in metres, > 0");
    e.ure_m = number(*it, "ure_m", e.ure_m, src, p, 1e-3, 1e4, "a σ_URE in metres, > 0");
    e.bnom_m = number(*it, "bnom_m", e.bnom_m, src, p, 0.0, 1e4, "a nominal bias in metres, >= 0");
    e.psat = probability(*it, "psat", e.psat, src, p);
    e.pconst = probability(*it, "pconst", e.pconst, src, p);
  }
}

namespace {

SatLook readSatellite(const json& s, const std::string& p, const std::string& src, std::set<SatId>& seen) {
  if (!s.is_object()) throw ParseError(src, 0, p, shown(s), "an object {id, az_deg, el_deg}");
  requireKeys(s, {"id", "az_deg", "el_deg"}, src, p);
  const auto id_it = s.find("id");
  if (id_it == s.end() || !id_it->is_string()) {
    throw ParseError(src, 0, p + ".id", id_it == s.end() ? "" : shown(*id_it), "a satellite id such as \"G01\"");
  }
  const auto id = parseSatId(id_it->get<std::string>());
  if (!id || !std::isalpha(static_cast<unsigned char>(id_it->get<std::string>()[0]))) {
    throw ParseError(src, 0, p + ".id", id_it->get<std::string>(),
                     "a letter G, E, R or C followed by a PRN, such as \"G01\"");
  }
  if (!seen.insert(*id).second) throw ParseError(src, 0, p + ".id", id->str(), "each satellite listed once");
  if (s.find("az_deg") == s.end()) throw ParseError(src, 0, p + ".az_deg", "", "an azimuth in degrees");
  if (s.find("el_deg") == s.end()) throw ParseError(src, 0, p + ".el_deg", "", "an elevation in degrees");
  SatLook look;
  look.sat = *id;
  look.look.azimuth_rad = maps::deg2rad(number(s, "az_deg", 0, src, p, -360.0, 360.0, "an azimuth in degrees in [-360, 360]"));
  look.look.elevation_rad = maps::deg2rad(number(s, "el_deg", 0, src, p, -90.0, 90.0, "an elevation in degrees in [-90, 90]"));
  return look;
}

std::vector<SatLook> readSatellites(const json& doc, const std::string& src) {
  const auto sats = doc.find("satellites");
  if (sats == doc.end() || !sats->is_array()) {
    throw ParseError(src, 0, "satellites", sats == doc.end() ? "" : shown(*sats), "an array of {id, az_deg, el_deg}");
  }
  std::vector<SatLook> out;
  std::set<SatId> seen;
  for (std::size_t i = 0; i < sats->size(); ++i) {
    out.push_back(readSatellite((*sats)[i], "satellites[" + std::to_string(i) + "]", src, seen));
  }
  return out;
}

/// "user_error_model": one model name, or an object of them per constellation (and "default").
void readUserErrorModel(const json& v, ErrorModel& model, const std::string& src) {
  if (v.is_string()) {
    model.setUserModel(userModel(v, src, "user_error_model"));
  } else if (v.is_object()) {
    if (const auto d = v.find("default"); d != v.end()) model.setUserModel(userModel(*d, src, "user_error_model.default"));
    for (auto e = v.begin(); e != v.end(); ++e) {
      if (e.key() == "default") continue;
      const auto c = constellationFromName(e.key());
      if (!c) throw ParseError(src, 0, "user_error_model." + e.key(), e.key(), "\"default\" or a constellation name");
      model.user_model[static_cast<int>(*c)] = userModel(*e, src, "user_error_model." + e.key());
    }
  } else {
    throw ParseError(src, 0, "user_error_model", shown(v), "a model name or an object of them per constellation");
  }
}

void readRequirements(const json& r, Requirements& q, const std::string& src) {
  if (!r.is_object()) throw ParseError(src, 0, "requirements", shown(r), "an object");
  requireKeys(r, {"phmi_vert", "phmi_hor", "pfa_vert", "pfa_hor", "p_thres", "p_emt", "tol_pl_m", "val_m", "hal_m",
                  "emt_m", "sigma_acc_m"}, src, "requirements");
  q.phmi_vert = probability(r, "phmi_vert", q.phmi_vert, src, "requirements");
  q.phmi_hor = probability(r, "phmi_hor", q.phmi_hor, src, "requirements");
  q.pfa_vert = probability(r, "pfa_vert", q.pfa_vert, src, "requirements");
  q.pfa_hor = probability(r, "pfa_hor", q.pfa_hor, src, "requirements");
  q.p_thres = probability(r, "p_thres", q.p_thres, src, "requirements");
  q.p_emt = probability(r, "p_emt", q.p_emt, src, "requirements");
  q.tol_pl_m = number(r, "tol_pl_m", q.tol_pl_m, src, "requirements", 1e-6, 100.0, "a tolerance in metres in (0, 100]");
  q.val_m = number(r, "val_m", q.val_m, src, "requirements", 0.0, 1e6, "an alert limit in metres >= 0");
  q.hal_m = number(r, "hal_m", q.hal_m, src, "requirements", 0.0, 1e6, "an alert limit in metres >= 0");
  q.emt_m = number(r, "emt_m", q.emt_m, src, "requirements", 0.0, 1e6, "a limit in metres >= 0");
  q.sigma_acc_m = number(r, "sigma_acc_m", q.sigma_acc_m, src, "requirements", 0.0, 1e6, "a limit in metres >= 0");
}

/// `block`.exclusion_pl: "allocated" or "remaining_geometry" (docs/method.md §3.2a, §4.3).
ExclusionPl exclusionPl(const json& block, ExclusionPl fallback, const std::string& src, const std::string& name) {
  const auto e = block.find("exclusion_pl");
  if (e == block.end()) return fallback;
  if (*e == "allocated") return ExclusionPl::kAllocated;
  if (*e == "remaining_geometry") return ExclusionPl::kRemainingGeometry;
  throw ParseError(src, 0, name + ".exclusion_pl", shown(*e), "\"allocated\" or \"remaining_geometry\"");
}

void readRaim(const json& r, RaimConfig& raim, const std::string& src) {
  if (!r.is_object()) throw ParseError(src, 0, "raim", shown(r), "an object");
  requireKeys(r, {"pfa", "pmd", "formula", "max_exclusions", "exclusion_pl"}, src, "raim");
  raim.pfa = probability(r, "pfa", raim.pfa, src, "raim");
  raim.pmd = probability(r, "pmd", raim.pmd, src, "raim");
  raim.max_exclusions = static_cast<int>(number(r, "max_exclusions", raim.max_exclusions, src, "raim", 0, 10, "0 to 10"));
  if (const auto f = r.find("formula"); f != r.end()) {
    if (*f == "pbias_plus_noise") raim.formula = RaimPlFormula::kSlopePbiasPlusNoise;
    else if (*f == "brown") raim.formula = RaimPlFormula::kSlopePbias;
    else throw ParseError(src, 0, "raim.formula", shown(*f), "\"pbias_plus_noise\" or \"brown\"");
  }
  raim.exclusion_pl = exclusionPl(r, raim.exclusion_pl, src, "raim");
}

void readAraim(const json& a, AraimConfig& araim, const std::string& src) {
  if (!a.is_object()) throw ParseError(src, 0, "araim", shown(a), "an object");
  requireKeys(a, {"fault_mode_rule", "fc_thres", "emt_probability", "horizontal_only", "exclusion_pl",
                  "exclude_constellations"}, src, "araim");
  araim.exclusion_pl = exclusionPl(a, araim.exclusion_pl, src, "araim");
  if (const auto x = a.find("exclude_constellations"); x != a.end()) {
    if (!x->is_boolean()) throw ParseError(src, 0, "araim.exclude_constellations", shown(*x), "true or false");
    araim.exclude_constellations = x->get<bool>();
  }
  if (const auto f = a.find("fault_mode_rule"); f != a.end()) {
    if (*f == "adds_until_threshold") araim.rule = FaultModeRule::kAddsUntilThreshold;
    else if (*f == "joint_events") araim.rule = FaultModeRule::kJointEvents;
    else if (*f == "blanch2012") araim.rule = FaultModeRule::kBlanch2012;
    else {
      throw ParseError(src, 0, "araim.fault_mode_rule", shown(*f),
                       "\"adds_until_threshold\", \"joint_events\" or \"blanch2012\"");
    }
  }
  araim.fc_thres = number(a, "fc_thres", araim.fc_thres, src, "araim", 0.0, 1.0, "a fraction in [0, 1)");
  if (araim.fc_thres >= 1.0) throw ParseError(src, 0, "araim.fc_thres", shown(a.at("fc_thres")), "a fraction in [0, 1)");
  if (const auto e = a.find("emt_probability"); e != a.end()) {
    if (*e == "mode_prior") araim.emt_probability = EmtProbability::kModePrior;
    else if (*e == "event_product") araim.emt_probability = EmtProbability::kEventProduct;
    else throw ParseError(src, 0, "araim.emt_probability", shown(*e), "\"mode_prior\" or \"event_product\"");
  }
  if (const auto h = a.find("horizontal_only"); h != a.end()) {
    if (!h->is_boolean()) throw ParseError(src, 0, "araim.horizontal_only", shown(*h), "true or false");
    araim.horizontal_only = h->get<bool>();
  }
}

maps::Geodetic readPosition(const json& p, const std::string& src) {
  if (!p.is_object()) throw ParseError(src, 0, "position", shown(p), "an object {lat_deg, lon_deg, h_m}");
  requireKeys(p, {"lat_deg", "lon_deg", "h_m"}, src, "position");
  maps::Geodetic g;
  g.lat_rad = maps::deg2rad(number(p, "lat_deg", 0, src, "position", -90, 90, "a latitude in [-90, 90] degrees"));
  g.lon_rad = maps::deg2rad(number(p, "lon_deg", 0, src, "position", -180, 360, "a longitude in degrees"));
  g.h_ell_m = number(p, "h_m", 0, src, "position", -1e4, 1e6, "an ellipsoidal height in metres");
  return g;
}

}  // namespace

GeometryInput parseGeometry(const json& doc, const std::string& src) {
  GeometryInput in;
  if (!doc.is_object()) throw ParseError(src, 0, "(document)", shown(doc), "a JSON object with a \"satellites\" array");
  requireKeys(doc, {"satellites", "ism", "user_error_model", "requirements", "raim", "araim", "position", "iono_tau_vert_m"},
              src, "");
  in.satellites = readSatellites(doc, src);
  if (const auto it = doc.find("ism"); it != doc.end()) parseIsm(*it, in.model, src, "ism");
  if (const auto it = doc.find("user_error_model"); it != doc.end()) readUserErrorModel(*it, in.model, src);
  if (const auto it = doc.find("requirements"); it != doc.end()) readRequirements(*it, in.requirements, src);
  in.raim.phmi_hor = in.requirements.phmi_hor;
  in.raim.phmi_vert = in.requirements.phmi_vert;
  if (const auto it = doc.find("raim"); it != doc.end()) readRaim(*it, in.raim, src);
  in.araim.requirements = in.requirements;
  if (const auto it = doc.find("araim"); it != doc.end()) readAraim(*it, in.araim, src);
  if (const auto it = doc.find("position"); it != doc.end()) in.position = readPosition(*it, src);
  in.tau_vert_m = in.position ? ionoTauVert_m(geomagneticLatitude(*in.position)) : 9.0;
  if (doc.find("iono_tau_vert_m") != doc.end()) {
    in.tau_vert_m = number(doc, "iono_tau_vert_m", 9.0, src, "", 0.0, 100.0, "a vertical ionospheric bound in metres");
    in.model.iono_tau_vert_m = in.tau_vert_m;
  }
  return in;
}

GeometryInput loadGeometryFile(const std::string& path) { return parseGeometry(maps::readJsonFile(path), path); }

}  // namespace skylane::integrity
