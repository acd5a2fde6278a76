#include "cli/integrity_commands.hpp"

#include "cli/progress.hpp"

#include "cli/skymask_commands.hpp"
#include "cli/svg_plot.hpp"
#include "integrity/araim/exclusion.hpp"
#include "integrity/availability.hpp"
#include "integrity/geometry_file.hpp"
#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/parse_error.hpp"
#include "integrity/predict.hpp"
#include "integrity/raim/spp.hpp"
#include "maps/atomic_file.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <unistd.h>

namespace skylane::cli {
namespace {

using integrity::ParseError;
using nlohmann::json;

/// Rounds to 4 decimals (0.1 mm / 1e-4 of a unit); null when not finite (JSON has no NaN).
json r4(double v) { return std::isfinite(v) ? json(std::round(v * 1e4) / 1e4) : json(nullptr); }

json satList(const std::vector<integrity::SatId>& sats) {
  json a = json::array();
  for (const auto& s : sats) a.push_back(s.str());
  return a;
}

json plJson(const integrity::RaimPl& pl, const integrity::Requirements& req, bool verbose,
            const std::vector<integrity::SatId>& sats) {
  json j;
  j["method"] = "raim";
  j["available"] = pl.available && pl.hpl_m <= req.hal_m && pl.vpl_m <= req.val_m;
  j["pl_computed"] = pl.available;
  if (!pl.reason.empty()) j["reason"] = pl.reason;
  j["hpl_m"] = pl.available ? r4(pl.hpl_m) : json(nullptr);
  j["vpl_m"] = pl.available ? r4(pl.vpl_m) : json(nullptr);
  j["hal_m"] = req.hal_m;
  j["val_m"] = req.val_m;
  j["satellites"] = sats.size();
  if (verbose && pl.available) {
    j["sigma_h_m"] = r4(pl.sigma_h_m);
    j["sigma_v_m"] = r4(pl.sigma_v_m);
    j["dof"] = pl.thresholds.dof;
    j["threshold"] = r4(pl.thresholds.threshold);
    j["p_bias"] = r4(pl.thresholds.p_bias);
    j["max_hslope"] = r4(pl.max_hslope);
    j["max_vslope"] = r4(pl.max_vslope);
    j["critical_sat_h"] = sats[static_cast<std::size_t>(pl.critical_sat_h)].str();
    j["critical_sat_v"] = sats[static_cast<std::size_t>(pl.critical_sat_v)].str();
    json per = json::array();
    for (std::size_t i = 0; i < sats.size(); ++i) {
      per.push_back({{"id", sats[i].str()},
                     {"hslope", r4(pl.hslope[static_cast<Eigen::Index>(i)])},
                     {"vslope", r4(pl.vslope[static_cast<Eigen::Index>(i)])}});
    }
    j["per_satellite"] = per;
  }
  return j;
}

/// The stream of an output option: standard output for "" or "-", else a file staged in
/// `outputs` (written in place only when the command has succeeded: maps/atomic_file.hpp).
std::ostream& outputStream(maps::OutputSet& outputs, const std::string& path, const char* option) {
  if (path.empty() || path == "-") return std::cout;
  return outputs.add(path, option);
}

/// Reads a JSON file holding an ISM (either {"ism":{…}} or the bare object) into `model`.
void applyIsmFile(const std::string& path, integrity::ErrorModel& model) {
  const json doc = maps::readJsonFile(path);
  integrity::parseIsm(doc.contains("ism") ? doc["ism"] : doc, model, path, "ism");
}

/// Loads every almanac and navigation file given on the command line.
integrity::OrbitSource loadOrbits(const std::vector<std::string>& almanacs, const std::vector<std::string>& navs) {
  integrity::OrbitSource orbits;
  for (const auto& a : almanacs) orbits.addAlmanac(integrity::loadAlmanac(a), a);
  for (const auto& n : navs) orbits.addNavigation(integrity::loadRinexNav(n), n);
  if (orbits.empty()) throw ParseError("--almanac", 0, "--almanac/--nav", "", "at least one almanac or navigation file");
  return orbits;
}

/// A validated --start / --duration / --step triple.
struct TimeWindow {
  integrity::GpsTime start;
  double duration_s = 0, step_s = 0;
};

TimeWindow parseTimeWindow(const std::string& start, const std::string& duration, const std::string& step,
                           double max_epochs) {
  TimeWindow w;
  const auto t = integrity::parseRfc3339(start);
  if (!t) throw ParseError("--start", 0, "--start", start, "an RFC 3339 UTC time such as 2026-11-23T14:00:00Z");
  const auto d = integrity::parseDuration(duration);
  if (!d) throw ParseError("--duration", 0, "--duration", duration, "a duration such as 24h, 90m, 3600s");
  const auto s = integrity::parseDuration(step);
  if (!s) throw ParseError("--step", 0, "--step", step, "a duration such as 10m or 30s");
  if (*d / *s > max_epochs) {
    throw ParseError("--step", 0, "--step", step, "at most " + std::to_string(static_cast<long>(max_epochs)) + " epochs in --duration");
  }
  w.start = *t;
  w.duration_s = *d;
  w.step_s = *s;
  return w;
}

/// Heights a GNSS user can have: below the Dead Sea shore to the top of the atmosphere (100 km,
/// where the troposphere model and the sky mask end); beyond, the signal geometry is garbage.
constexpr double kMinUserHeight_m = -1000.0, kMaxUserHeight_m = 100e3;

double parseUserHeight(double alt_m) {
  if (!(alt_m >= kMinUserHeight_m && alt_m <= kMaxUserHeight_m)) {
    char value[32];
    std::snprintf(value, sizeof value, "%g", alt_m);
    throw ParseError("--alt", 0, "--alt", value, "an ellipsoidal height in [-1000, 100000] m");
  }
  return alt_m;
}

double parseMask(double mask_deg) {
  if (!(mask_deg >= 0 && mask_deg < 90)) {
    throw ParseError("--mask-deg", 0, "--mask-deg", std::to_string(mask_deg), "an elevation mask in [0, 90) degrees");
  }
  return maps::deg2rad(mask_deg);
}

json triple(const std::array<double, 3>& v) { return json::array({r4(v[0]), r4(v[1]), r4(v[2])}); }

/// The predicted PLs of a user who excludes (docs/method.md §4.3, step 5): the maximum over the
/// no-exclusion outcome and every candidate's, each with ρ = 1/(N_exc + 1) of the budget.
json afterExclusionJson(const integrity::Geometry& g, const integrity::GeometryInput& in) {
  const integrity::AraimResult r = integrity::araimFdeProtectionLevels(g, in.model, in.araim);
  json j;
  j["exclusion_candidates"] = integrity::exclusionCandidates(g, in.model, in.araim).size();
  j["budget_share"] = r.budget_share;
  j["pl_computed"] = r.pl_computed;
  j["available"] = r.available;
  if (!r.reason.empty()) j["reason"] = r.reason;
  j["hpl_m"] = r.pl_computed ? r4(r.hpl_m) : json(nullptr);
  j["vpl_m"] = r.pl_computed ? r4(r.vpl_m) : json(nullptr);
  return j;
}

json araimJson(const integrity::AraimResult& r, bool verbose, const std::vector<integrity::SatId>& sats) {
  json j;
  j["method"] = "araim";
  j["available"] = r.available;
  j["pl_computed"] = r.pl_computed;
  if (!r.reason.empty()) j["reason"] = r.reason;
  const bool ok = r.pl_computed;
  j["hpl_m"] = ok ? r4(r.hpl_m) : json(nullptr);
  j["vpl_m"] = ok ? r4(r.vpl_m) : json(nullptr);
  j["hpl_equal_allocation_m"] = ok ? r4(r.hpl_equal_allocation_m) : json(nullptr);
  j["vpl_equal_allocation_m"] = ok ? r4(r.vpl_equal_allocation_m) : json(nullptr);
  // EMT and σ_acc need only the all-in-view solution and the thresholds: printed also when the
  // PL is not computable (as MAAST for ARAIM reports them).
  const bool acc = r.accuracy_computed;
  j["emt_m"] = acc ? r4(r.emt_m) : json(nullptr);
  j["sigma_acc_m"] = acc ? r4(r.sigma_acc_v_m) : json(nullptr);
  j["fault_modes"] = r.fault_modes;
  j["satellites"] = sats.size();
  if (verbose && acc) {
    j["n_fault_max"] = r.n_fault_max;
    j["p_not_monitored"] = r.p_not_monitored;
    j["k_fa_h"] = r4(r.k_fa_h);
    j["k_fa_v"] = r4(r.k_fa_v);
    j["hpl_axis_m"] = ok ? json{r4(r.hpl_axis_m[0]), r4(r.hpl_axis_m[1])} : json(nullptr);
    j["fault_free"] = {{"sigma_m", triple(r.sigma0)}, {"bias_m", triple(r.bias0)}};
    json subsets = json::array();
    for (const auto& s : r.subsets) {
      json removed = json::array();
      for (int i : s.removed) removed.push_back(sats[static_cast<std::size_t>(i)].str());
      subsets.push_back({{"removed", removed},
                         {"prior", s.prior},
                         {"sigma_m", triple(s.sigma)},
                         {"sigma_ss_m", triple(s.sigma_ss)},
                         {"bias_m", triple(s.bias)},
                         {"threshold_m", triple(s.threshold)}});
    }
    j["subsets"] = subsets;
  }
  return j;
}

integrity::IntegrityMethod parseMethod(const std::string& m) {
  if (m == "araim") return integrity::IntegrityMethod::kAraim;
  if (m == "raim") return integrity::IntegrityMethod::kRaim;
  throw ParseError("--method", 0, "--method", m, "araim or raim");
}

// ---------------------------------------------------------------------------
struct PlOptions {
  std::string geometry;
  std::string method = "araim";
  bool verbose = false;
};

void runPl(const PlOptions& o) {
  const integrity::IntegrityMethod method = parseMethod(o.method);
  const integrity::GeometryInput in = integrity::loadGeometryFile(o.geometry);
  const integrity::Geometry g = integrity::buildGeometry(in.satellites, in.model, in.tau_vert_m);
  if (method == integrity::IntegrityMethod::kAraim) {
    json j = araimJson(integrity::araimProtectionLevels(g, in.model, in.araim), o.verbose, g.sats);
    if (in.araim.exclusion_pl == integrity::ExclusionPl::kAllocated) j["after_exclusion"] = afterExclusionJson(g, in);
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << plJson(integrity::raimProtectionLevels(g, in.raim), in.requirements, o.verbose, g.sats).dump(2) << "\n";
  }
}

// ---------------------------------------------------------------------------
struct PredictOptions {
  std::vector<std::string> almanacs;
  std::vector<std::string> navs;
  double lat_deg = NAN, lon_deg = NAN, alt_m = 0.0;
  std::string start;
  std::string duration = "24h";
  std::string step = "10m";
  double mask_deg = 5.0;
  std::string format = "csv";
  std::string output;
  std::string plot;
  std::string ism;
  std::string user_model = "dual_frequency";
  std::string method = "araim";
  bool with_exclusion = false;
  bool progress = false;
  std::string buildings;
  std::string terrain;
  std::optional<double> ground_amsl_m;
};

/// The request the options describe: place, time window, mask, error model, sky mask.
integrity::PredictRequest predictRequest(const PredictOptions& o) {
  integrity::PredictRequest req;
  if (!(o.lat_deg >= -90 && o.lat_deg <= 90)) throw ParseError("--lat", 0, "--lat", std::to_string(o.lat_deg), "a latitude in [-90, 90] degrees");
  if (!(o.lon_deg >= -180 && o.lon_deg <= 360)) throw ParseError("--lon", 0, "--lon", std::to_string(o.lon_deg), "a longitude in degrees");
  req.place = {maps::deg2rad(o.lat_deg), maps::deg2rad(o.lon_deg), parseUserHeight(o.alt_m)};
  const TimeWindow window = parseTimeWindow(o.start, o.duration, o.step, 1e6);
  req.start = window.start;
  req.duration_s = window.duration_s;
  req.step_s = window.step_s;
  req.mask_rad = parseMask(o.mask_deg);
  if (o.user_model == "single_frequency") req.model.setUserModel(integrity::UserErrorModel::kSingleFrequency);
  else if (o.user_model != "dual_frequency") throw ParseError("--user-model", 0, "--user-model", o.user_model, "dual_frequency or single_frequency");
  if (!o.ism.empty()) applyIsmFile(o.ism, req.model);
  req.with_exclusion = o.with_exclusion;
  if (o.format != "csv" && o.format != "jsonl") throw ParseError("--format", 0, "--format", o.format, "csv or jsonl");

  if (!o.buildings.empty() || !o.terrain.empty()) {
    // Satellites behind the buildings and terrain around the place are dropped (--alt is the antenna).
    const maps::Terrain ground = groundModel(o.terrain, o.ground_amsl_m);
    req.sky_mask = skyMaskAt(req.place, o.buildings, ground, !o.terrain.empty(), maps::SkyMaskOptions{});
  }
  return req;
}

/// Every orbit file's age at --start (integrity/gnss/orbit_age.hpp): past its warning limit a
/// warning on stderr, past its error limit a ParseError (exit 2).
void checkOrbitAges(const integrity::OrbitSource& orbits, const integrity::GpsTime& start) {
  for (const integrity::OrbitFileAge& age : orbits.fileAges(start)) {
    const std::string warning = integrity::requireUsableAge(age, "--start");
    if (!warning.empty()) std::cerr << "skylane: warning: " << warning << "\n";
  }
}

std::string predictCsvLine(const integrity::PredictSample& s, integrity::IntegrityMethod method) {
  const bool ok = s.pl.pl_computed, ar = method == integrity::IntegrityMethod::kAraim;
  char buf[320];
  std::snprintf(buf, sizeof buf, "%s,%d,%.1f,%zu,%.3f,%.3f,%.3f,%.3f,%d,%.3f,%.3f,%d\n",
                integrity::formatRfc3339(s.t).c_str(), s.t.week, s.t.sow, s.sats.size(), s.dops.hdop, s.dops.vdop,
                ok ? s.pl.hpl_m : NAN, ok ? s.pl.vpl_m : NAN, s.pl.available ? 1 : 0, ok && ar ? s.pl.emt_m : NAN,
                ok && ar ? s.pl.sigma_acc_m : NAN, s.pl.fault_modes);
  return buf;
}

json predictJsonLine(const integrity::PredictSample& s, const std::string& method_name,
                     integrity::IntegrityMethod method, bool has_sky_mask, bool with_exclusion) {
  std::vector<integrity::SatId> ids;
  for (const auto& l : s.sats) ids.push_back(l.sat);
  const bool ok = s.pl.pl_computed;
  json j;
  j["time"] = integrity::formatRfc3339(s.t);
  j["method"] = method_name;
  if (with_exclusion) j["with_exclusion"] = true;
  j["available"] = s.pl.available;
  j["pl_computed"] = ok;
  if (!s.pl.reason.empty()) j["reason"] = s.pl.reason;
  j["hpl_m"] = ok ? r4(s.pl.hpl_m) : json(nullptr);
  j["vpl_m"] = ok ? r4(s.pl.vpl_m) : json(nullptr);
  if (method == integrity::IntegrityMethod::kAraim) {
    j["emt_m"] = ok ? r4(s.pl.emt_m) : json(nullptr);
    j["sigma_acc_m"] = ok ? r4(s.pl.sigma_acc_m) : json(nullptr);
    j["fault_modes"] = s.pl.fault_modes;
  }
  j["hdop"] = r4(s.dops.hdop);
  j["vdop"] = r4(s.dops.vdop);
  j["satellites"] = satList(ids);
  if (has_sky_mask) j["blocked_by_sky_mask"] = s.blocked;
  return j;
}

/// The samples as CSV (with a header line) or JSON lines, to --output or stdout.
void writePredictSamples(std::ostream& out, const std::vector<integrity::PredictSample>& samples, const PredictOptions& o,
                         integrity::IntegrityMethod method, bool has_sky_mask) {
  if (o.format == "csv") {
    out << "time_utc,gps_week,gps_sow,satellites,hdop,vdop,hpl_m,vpl_m,available,emt_m,sigma_acc_m,fault_modes\n";
  }
  for (const auto& s : samples) {
    if (o.format == "csv") {
      out << predictCsvLine(s, method);
    } else {
      out << predictJsonLine(s, o.method, method, has_sky_mask, o.with_exclusion).dump() << "\n";
    }
  }
}

/// The --plot SVG: protection levels against the alert limits, and the satellites in view.
void writePredictPlot(std::ostream& out, const std::vector<integrity::PredictSample>& samples, const integrity::PredictRequest& req,
                      const PredictOptions& o, integrity::IntegrityMethod method) {
  const integrity::Requirements& limits = req.araim.requirements;
  std::vector<double> x, hpl, vpl, hal, val, nsat;
  for (const auto& s : samples) {
    x.push_back(s.t - req.start);
    hpl.push_back(s.pl.pl_computed ? s.pl.hpl_m : NAN);
    vpl.push_back(s.pl.pl_computed ? s.pl.vpl_m : NAN);
    hal.push_back(limits.hal_m);
    val.push_back(limits.val_m);
    nsat.push_back(static_cast<double>(s.sats.size()));
  }
  char title[200];
  std::snprintf(title, sizeof title, "%s protection levels%s at %.4f°, %.4f°, %.0f m from %s",
                method == integrity::IntegrityMethod::kAraim ? "ARAIM" : "RAIM", o.with_exclusion ? " with exclusion" : "", o.lat_deg,
                o.lon_deg, o.alt_m, integrity::formatRfc3339(req.start).c_str());
  const std::string svg = renderTimeSeriesSvg(
      title, "time since start",
      x,
      {Panel{"protection level [m]",
             {{"HPL", "#1f77b4", hpl}, {"VPL", "#d62728", vpl}, {"HAL", "#1f77b4", hal, true}, {"VAL", "#d62728", val, true}}},
       Panel{"satellites in view", {{"satellites", "#2ca02c", nsat, false, true}}, 160}});
  out << svg;
}

void runPredict(const PredictOptions& o) {
  const integrity::IntegrityMethod method = parseMethod(o.method);
  const integrity::PredictRequest req = predictRequest(o);
  const integrity::OrbitSource orbits = loadOrbits(o.almanacs, o.navs);
  checkOrbitAges(orbits, req.start);
  maps::OutputSet outputs;  // staged first: a path that cannot be written fails before the work
  std::ostream& out = outputStream(outputs, o.output, "--output");
  std::ostream* plot = o.plot.empty() ? nullptr : &outputs.add(o.plot, "--plot");
  Progress bar("predict", o.progress);
  const auto samples = integrity::predictIntegrity(orbits, req, method, std::ref(bar));
  writePredictSamples(out, samples, o, method, req.sky_mask.has_value());
  if (plot) writePredictPlot(*plot, samples, req, o, method);
  outputs.commit();
}

// ---------------------------------------------------------------------------
struct SppOptions {
  std::string obs;
  std::vector<std::string> navs;
  double mask_deg = 15.0;
  std::string iono = "auto";
  std::string output;
  std::vector<std::string> inject;
  bool progress = false;
  bool no_galileo = false;
  std::string method = "raim";
};

void runSpp(const SppOptions& o) {
  integrity::SppConfig cfg;
  cfg.elevation_mask_rad = parseMask(o.mask_deg);
  if (o.iono == "auto") cfg.iono = integrity::IonoMode::kAuto;
  else if (o.iono == "iono_free") cfg.iono = integrity::IonoMode::kIonoFree;
  else if (o.iono == "klobuchar") cfg.iono = integrity::IonoMode::kKlobuchar;
  else throw ParseError("--iono", 0, "--iono", o.iono, "auto, iono_free or klobuchar");
  cfg.use_galileo = !o.no_galileo;
  cfg.method = parseMethod(o.method);
  for (const std::string& inj : o.inject) {  // "G05:50"
    const auto colon = inj.find(':');
    const auto sat = integrity::parseSatId(inj.substr(0, colon));
    if (colon == std::string::npos || !sat) throw ParseError("--inject", 0, "--inject", inj, "SAT:BIAS_M such as G05:50");
    cfg.injected_bias_m[*sat] = integrity::parseFortranReal(inj.substr(colon + 1), "--inject", 0, "--inject bias");
  }
  const integrity::ObservationData obs = integrity::loadRinexObs(o.obs);
  integrity::NavigationData nav;
  for (const auto& n : o.navs) nav.merge(integrity::loadRinexNav(n));
  maps::OutputSet outputs;
  std::ostream& out = outputStream(outputs, o.output, "--output");
  Progress bar("spp", o.progress);
  const auto epochs = integrity::solveSpp(obs, nav, cfg, std::ref(bar));
  for (const auto& e : epochs) {
    json j;
    j["time"] = integrity::formatRfc3339(e.t, 3);
    j["gps_week"] = e.t.week;
    j["gps_sow"] = std::round(e.t.sow * 1e6) / 1e6;  // µs: drop binary round-off
    j["solved"] = e.solved;
    if (e.solved) {
      char lat[32], lon[32];
      std::snprintf(lat, sizeof lat, "%.9f", maps::rad2deg(e.position.lat_rad));
      std::snprintf(lon, sizeof lon, "%.9f", maps::rad2deg(e.position.lon_rad));
      j["lat_deg"] = json::parse(lat);
      j["lon_deg"] = json::parse(lon);
      j["h_ell_m"] = r4(e.position.h_ell_m);
      j["ecef_m"] = {r4(e.p_ecef.x()), r4(e.p_ecef.y()), r4(e.p_ecef.z())};
      j["iono"] = e.iono_free ? "iono_free" : "klobuchar";
      j["used"] = satList(e.used);
      j["excluded"] = satList(e.excluded);
      j["fault_detected"] = e.fault_detected;
      j["test_statistic"] = r4(e.test_statistic);
      j["threshold"] = r4(e.threshold);
      j["method"] = o.method;
      j["hpl_m"] = e.pl.pl_computed ? r4(e.pl.hpl_m) : json(nullptr);
      j["vpl_m"] = e.pl.pl_computed ? r4(e.pl.vpl_m) : json(nullptr);
      j["pl_computed"] = e.pl.pl_computed;
      j["available"] = e.pl.available;
      if (o.method == "araim" && e.pl.pl_computed) {
        j["emt_m"] = r4(e.pl.emt_m);
        j["sigma_acc_m"] = r4(e.pl.sigma_acc_m);
        j["fault_modes"] = e.pl.fault_modes;
      }
    }
    if (!e.note.empty()) j["note"] = e.note;
    out << j.dump() << "\n";
  }
  outputs.commit();
}

// ---------------------------------------------------------------------------
struct AvailabilityOptions {
  std::vector<std::string> almanacs;
  std::vector<std::string> navs;
  double grid_deg = 5.0;
  std::string start = "2017-01-01T00:00:00Z";
  std::string duration = "24h";
  std::string step = "10m";
  double mask_deg = 5.0;
  double alt_m = 0.0;
  std::string method = "araim";
  std::string ism;
  std::string output;
  std::string map;
  int threads = 0;
  bool horizontal_only = false;
  bool with_exclusion = false;
  bool progress = false;
};

void runAvailability(const AvailabilityOptions& o) {
  integrity::AvailabilityRequest req;
  req.method = parseMethod(o.method);
  if (!(o.grid_deg >= 0.5 && o.grid_deg <= 30)) {
    throw ParseError("--grid-deg", 0, "--grid-deg", std::to_string(o.grid_deg), "a grid step in [0.5, 30] degrees");
  }
  req.grid_deg = o.grid_deg;
  const TimeWindow window = parseTimeWindow(o.start, o.duration, o.step, 1e5);
  req.start = window.start;
  req.duration_s = window.duration_s;
  req.step_s = window.step_s;
  req.mask_rad = parseMask(o.mask_deg);
  req.user_h_m = parseUserHeight(o.alt_m);
  if (o.threads < 0 || o.threads > 256) throw ParseError("--threads", 0, "--threads", std::to_string(o.threads), "0 (all cores) to 256");
  req.threads = o.threads;
  req.araim.horizontal_only = o.horizontal_only;
  req.with_exclusion = o.with_exclusion;
  if (!o.ism.empty()) applyIsmFile(o.ism, req.model);
  const integrity::OrbitSource orbits = loadOrbits(o.almanacs, o.navs);
  maps::OutputSet outputs;  // staged first: a path that cannot be written fails before the work
  std::ostream& out = outputStream(outputs, o.output, "--output");
  std::ostream* map_svg = o.map.empty() ? nullptr : &outputs.add(o.map, "--map");
  Progress bar("availability", o.progress);
  const integrity::AvailabilityMap map = integrity::computeAvailability(orbits, req, std::ref(bar));

  out << "lat_deg,lon_deg,epochs,available_epochs,availability_pct,max_hpl_m,max_vpl_m\n";
  std::vector<MapCell> cells;
  for (const auto& c : map.cells) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.2f,%.2f,%d,%d,%.3f,%.3f,%.3f\n", c.lat_deg, c.lon_deg, c.epochs, c.available,
                  c.percent(), c.max_hpl_m, c.max_vpl_m);
    out << buf;
    cells.push_back({c.lat_deg, c.lon_deg, c.percent()});
  }
  const double cov = map.coveragePercent(99.5);
  if (map_svg) {
    char title[200];
    std::snprintf(title, sizeof title, "%s%s availability%s, %s + %s, mask %.0f°, step %s", o.method == "araim" ? "ARAIM" : "RAIM",
                  o.with_exclusion ? " FDE" : "", o.horizontal_only ? " (horizontal)" : " (LPV-200)", integrity::formatRfc3339(req.start).c_str(),
                  o.duration.c_str(), o.mask_deg, o.step.c_str());
    char footer[200];
    std::snprintf(footer, sizeof footer, "%.1f° grid, %zu user-epochs; %.2f %% of the area has ≥ 99.5 %% availability",
                  o.grid_deg, map.user_epochs, cov);
    *map_svg << renderAvailabilityMapSvg(title, cells, o.grid_deg, footer);
  }
  outputs.commit();  // the summary only after the outputs are in place: a failed write is the one line said
  std::cerr << "skylane: " << map.user_epochs << " user-epochs; " << std::fixed << std::setprecision(2) << cov
            << " % of the Earth's area has >= 99.5 % availability\n";
}

}  // namespace

void addIntegrityCommands(CLI::App& app) {
  CLI::App* integ = app.add_subcommand("integrity", "GNSS integrity: protection levels, prediction, positioning");
  integ->require_subcommand(1);

  auto pl = std::make_shared<PlOptions>();
  CLI::App* c = integ->add_subcommand("pl", "protection levels for one geometry file (JSON)");
  c->add_option("--geometry", pl->geometry, "geometry JSON: satellites (id, az_deg, el_deg), ism, requirements")->required();
  c->add_option("--method", pl->method, "integrity method: araim (default) or raim");
  c->add_flag("--verbose", pl->verbose, "per-satellite slopes and thresholds");
  c->callback([pl] { runPl(*pl); });

  auto pr = std::make_shared<PredictOptions>();
  c = integ->add_subcommand("predict", "protection levels over time at one place (ARAIM or RAIM)");
  c->add_option("--almanac", pr->almanacs, "YUMA or SEM almanac (repeatable)");
  c->add_option("--nav", pr->navs, "RINEX navigation file (repeatable)");
  c->add_option("--lat", pr->lat_deg, "latitude [deg]")->required();
  c->add_option("--lon", pr->lon_deg, "longitude [deg]")->required();
  c->add_option("--alt", pr->alt_m, "ellipsoidal height [m]");
  c->add_option("--start", pr->start, "start, RFC 3339 UTC (2026-11-23T14:00:00Z)")->required();
  c->add_option("--duration", pr->duration, "duration (24h, 90m, 3600s)");
  c->add_option("--step", pr->step, "time step (10m, 30s)");
  c->add_option("--mask-deg", pr->mask_deg, "elevation mask [deg]");
  c->add_option("--format", pr->format, "csv or jsonl");
  c->add_option("--output,-o", pr->output, "output file (default stdout)");
  c->add_option("--plot", pr->plot, "write an SVG plot of HPL/VPL and satellites in view");
  c->add_option("--ism", pr->ism, "JSON file with an ism object overriding the defaults");
  c->add_option("--user-model", pr->user_model, "dual_frequency or single_frequency");
  c->add_option("--method", pr->method, "integrity method: araim (default) or raim");
  c->add_flag("--fde", pr->with_exclusion, "PLs of a user who detects and excludes: the worst exclusion outcome, each with its share of the budget");
  c->add_option("--buildings", pr->buildings, "GeoJSON buildings: drop satellites behind them (sky mask at the place)");
  c->add_option("--terrain", pr->terrain, "terrain raster: ground under --buildings, and drop satellites behind the terrain");
  c->add_option("--ground-amsl", pr->ground_amsl_m, "flat ground under --buildings at this altitude AMSL [m] (default 0)");
  c->add_flag("--progress", pr->progress, "show a progress bar even when stderr is not a terminal");
  c->callback([pr] { runPredict(*pr); });

  auto av = std::make_shared<AvailabilityOptions>();
  c = integ->add_subcommand("availability", "worldwide availability map (percent of available epochs per grid point)");
  c->add_option("--almanac", av->almanacs, "YUMA or SEM almanac (repeatable)");
  c->add_option("--nav", av->navs, "RINEX navigation file (repeatable)");
  c->add_option("--grid-deg", av->grid_deg, "grid step [deg] (cells centred on the grid)");
  c->add_option("--start", av->start, "start, RFC 3339 UTC");
  c->add_option("--duration", av->duration, "duration (24h)");
  c->add_option("--step", av->step, "time step (10m)");
  c->add_option("--mask-deg", av->mask_deg, "elevation mask [deg]");
  c->add_option("--alt", av->alt_m, "user ellipsoidal height [m]");
  c->add_option("--method", av->method, "araim (default) or raim");
  c->add_option("--ism", av->ism, "JSON file with an ism object overriding the defaults");
  c->add_option("--output,-o", av->output, "CSV output (default stdout)");
  c->add_option("--map", av->map, "write an SVG world map with a colour scale");
  c->add_option("--threads", av->threads, "worker threads (0 = all cores)");
  c->add_flag("--horizontal-only", av->horizontal_only, "availability from HPL <= HAL only (H-ARAIM)");
  c->add_flag("--fde", av->with_exclusion, "PLs of a user who detects and excludes (worst exclusion outcome)");
  c->add_flag("--progress", av->progress, "show a progress bar even when stderr is not a terminal");
  c->callback([av] { runAvailability(*av); });

  auto sp = std::make_shared<SppOptions>();
  c = integ->add_subcommand("spp", "single-point positioning with RAIM FDE and protection levels per epoch");
  c->add_option("--obs", sp->obs, "RINEX 2/3 observation file")->required();
  c->add_option("--nav", sp->navs, "RINEX 2/3 navigation file (repeatable)")->required();
  c->add_option("--mask-deg", sp->mask_deg, "elevation mask [deg]");
  c->add_option("--iono", sp->iono, "auto, iono_free or klobuchar");
  c->add_option("--output,-o", sp->output, "output JSON-lines file (default stdout)");
  c->add_option("--inject", sp->inject, "fault injection SAT:BIAS_M (e.g. G05:50), repeatable");
  c->add_flag("--no-galileo", sp->no_galileo, "use GPS only");
  c->add_option("--method", sp->method, "raim (default: chi-square + w-test) or araim (solution separation)");
  c->add_flag("--progress", sp->progress, "show a progress bar even when stderr is not a terminal");
  c->callback([sp] { runSpp(*sp); });
}

}  // namespace skylane::cli
