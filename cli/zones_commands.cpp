#include "cli/zones_commands.hpp"

#include "airspace/applicability.hpp"
#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "airspace/vertical.hpp"
#include "airspace/zone_export.hpp"
#include "airspace/zone_geometry.hpp"
#include "cli/height_options.hpp"
#include "cli/json_numbers.hpp"
#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "maps/terrain.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <memory>

namespace skylane::cli {
namespace {

using nlohmann::json;
using maps::ParseError;

struct ValidateOptions {
  std::vector<std::string> files;
  std::string format = "auto";
  bool repair = false;
};

struct AtOptions {
  std::vector<std::string> files;
  std::string format = "auto";
  double lat_deg = NAN, lon_deg = NAN;
  HeightOptions height;
  std::string time;
  std::string terrain;
};

struct ExportOptions {
  std::vector<std::string> files;
  std::string format = "auto";
  std::string to = "geojson";
  std::string output;
  std::string terrain;
  bool repair = false;
};

airspace::ZoneFormat zoneFormat(const std::string& text) {
  const auto f = airspace::parseZoneFormat(text);
  if (!f) throw ParseError("--format", 0, "--format", text, "auto, ed269, ed318, geojson or qgc");
  return *f;
}

maps::Terrain loadTerrain(const std::string& path) {
  return path.empty() ? maps::Terrain::flat(0.0) : maps::Terrain::fromRaster(path);
}


void runValidate(const ValidateOptions& o) {
  bool all_ok = true;
  for (const std::string& path : o.files) {
    std::vector<airspace::Zone> zones;
    try {
      zones = airspace::readZoneFile(path, zoneFormat(o.format));
    } catch (const ParseError& e) {
      std::cout << path << ": INVALID: " << e.what() << "\n";
      all_ok = false;
      continue;
    }
    const airspace::ValidationReport report = airspace::validateZones(zones, o.repair);
    for (std::size_t i = 0; i < zones.size(); ++i) {
      std::string status = "ok";
      for (const airspace::ZoneIssue& issue : report.issues) {
        if (issue.zone != i || !issue.error) continue;
        if (!issue.repaired) status = "INVALID";
        else if (status == "ok") status = "repaired";
      }
      std::cout << airspace::describe(zones[i]) << ": " << status << " (" << zones[i].volumes.size() << " volume"
                << (zones[i].volumes.size() == 1 ? "" : "s") << ", "
                << airspace::restrictionLabel(zones[i]) << ")\n";
      for (const airspace::ZoneIssue& issue : report.issues) {
        if (issue.zone != i) continue;
        std::cout << "  " << (issue.error ? (issue.repaired ? "repaired: " : "error: ") : "note: ") << issue.what;
        if (issue.volume >= 0) std::cout << " [volume " << issue.volume;
        if (issue.vertex >= 0) std::cout << ", vertex " << issue.vertex;
        if (issue.volume >= 0) std::cout << "]";
        std::cout << "\n";
      }
    }
    std::cout << path << ": " << zones.size() << " zone" << (zones.size() == 1 ? "" : "s") << ", "
              << (report.ok() ? "valid" : "INVALID") << "\n";
    all_ok = all_ok && report.ok();
  }
  if (!all_ok) throw ExitStatus(2);
}

void runAt(const AtOptions& o) {
  if (!(std::abs(o.lat_deg) <= 90.0)) throw ParseError("--lat", 0, "--lat", std::to_string(o.lat_deg), "a latitude in [-90, 90]");
  if (!(std::abs(o.lon_deg) <= 180.0)) throw ParseError("--lon", 0, "--lon", std::to_string(o.lon_deg), "a longitude in [-180, 180]");
  const auto t = maps::parseRfc3339(o.time);
  if (!t) throw ParseError("--time", 0, "--time", o.time, "an RFC 3339 date-time such as 2026-11-23T14:00:00Z");
  const maps::Terrain terrain = loadTerrain(o.terrain);
  const maps::Geoid& geoid = maps::Geoid::egm96();
  const airspace::VerticalModel model{terrain, geoid};
  const airspace::LatLon p{maps::deg2rad(o.lat_deg), maps::deg2rad(o.lon_deg)};
  const double h_ell = ellipsoidalHeight(o.height, p.lat_rad, p.lon_rad, terrain, o.terrain, geoid);
  json out;
  out["position"] = {{"lat_deg", o.lat_deg}, {"lon_deg", o.lon_deg}, {"h_ell_m", roundToMm(h_ell)},
                     {"alt_amsl_m", roundToMm(geoid.amslFromEllipsoidal_m(p.lat_rad, p.lon_rad, h_ell))}};
  out["time"] = maps::formatRfc3339(*t);
  out["terrain"] = terrain.describe();
  json applies = json::array();
  json nearby = json::array();
  for (const std::string& path : o.files) {
    for (const airspace::Zone& z : airspace::loadZones(path, zoneFormat(o.format))) {
      const bool active = airspace::isActive(z, *t);
      for (std::size_t vi = 0; vi < z.volumes.size(); ++vi) {
        const airspace::Volume& v = z.volumes[vi];
        const airspace::Side side = airspace::horizontalSide(v.outline, p);
        const bool inside_h = side != airspace::Side::kOutside;
        if (!inside_h) continue;
        const auto floor = airspace::limitHeightEllipsoid_m(v.lower, false, p, model);
        const auto ceiling = airspace::limitHeightEllipsoid_m(v.upper, true, p, model);
        json j;
        j["zone"] = z.identifier;
        j["name"] = z.name;
        j["file"] = z.source;
        j["volume"] = vi;
        j["restriction"] = std::string(airspace::restrictionLabel(z));
        if (z.keep_in) j["keep_in"] = true;
        j["message"] = z.message;
        j["active"] = active;
        j["horizontal"] = side == airspace::Side::kInside ? "inside" : "on the boundary";
        j["floor"] = airspace::limitJson(v.lower);
        j["ceiling"] = airspace::limitJson(v.upper);
        j["floor_h_ell_m"] = floor ? metresOrNull(*floor) : json("unknown terrain");
        j["ceiling_h_ell_m"] = ceiling ? metresOrNull(*ceiling) : json("unknown terrain");
        const bool unknown = !floor || !ceiling;
        const bool inside_v = !unknown && h_ell >= *floor && h_ell <= *ceiling;
        std::string why = std::string(j["horizontal"].get<std::string>()) + " the outline";
        if (unknown) {
          why += "; the vertical limits need terrain that is not known here (counted as applying, on the safe side)";
        } else if (inside_v) {
          why += ", between floor and ceiling";
        } else {
          why += h_ell < *floor ? ", below the floor" : ", above the ceiling";
        }
        why += active ? "; active at this time" : "; not active at this time";
        j["why"] = why;
        const bool applies_here = (inside_v || unknown) && active;
        j["applies"] = applies_here;
        (applies_here ? applies : nearby).push_back(j);
      }
    }
  }
  out["applies"] = applies;
  out["inside_outline_but_not_applying"] = nearby;
  std::cout << out.dump(2) << "\n";
}

void runExport(const ExportOptions& o) {
  if (o.to != "geojson") throw ParseError("--to", 0, "--to", o.to, "geojson");
  const maps::Terrain terrain = loadTerrain(o.terrain);
  const airspace::VerticalModel model{terrain, maps::Geoid::egm96()};
  json features = json::array();
  for (const std::string& path : o.files) {
    for (const airspace::Zone& z : airspace::loadZones(path, zoneFormat(o.format), o.repair)) {
      for (json& f : airspace::zoneFeatures(z, model)) features.push_back(std::move(f));
    }
  }
  const json out = {{"type", "FeatureCollection"},
                    {"name", "skylane normalised zones"},
                    {"terrain", terrain.describe()},
                    {"features", features}};
  if (o.output.empty()) {
    std::cout << out.dump(1) << "\n";
  } else {
    maps::writeFileAtomically(o.output, out.dump(1) + "\n", "--output");
  }
}

}  // namespace

void addZonesCommands(CLI::App& app) {
  CLI::App* zones = app.add_subcommand("zones", "airspace zones: validate, query, export (ED-269, ED-318, GeoJSON, QGC)");
  zones->require_subcommand(1);

  auto va = std::make_shared<ValidateOptions>();
  CLI::App* c = zones->add_subcommand("validate", "check zone files; exit 0 when valid, 2 when not");
  c->add_option("files", va->files, "zone files")->required();
  c->add_option("--format", va->format, "auto (default), ed269, ed318, geojson or qgc");
  c->add_flag("--repair", va->repair, "fix what can be fixed on the safe side, and report it");
  c->callback([va] { runValidate(*va); });

  auto at = std::make_shared<AtOptions>();
  c = zones->add_subcommand("at", "the zones that apply at a point and time, and why");
  c->add_option("files", at->files, "zone files")->required();
  c->add_option("--format", at->format, "auto (default), ed269, ed318, geojson or qgc");
  c->add_option("--lat", at->lat_deg, "latitude [deg]")->required();
  c->add_option("--lon", at->lon_deg, "longitude [deg]")->required();
  addHeightOptions(*c, at->height, "height above ground [m]");
  c->add_option("--time", at->time, "RFC 3339 time")->required();
  c->add_option("--terrain", at->terrain, "terrain raster (GeoTIFF, ESRI ASCII, SRTM HGT); default flat at 0 m AMSL");
  c->callback([at] { runAt(*at); });

  auto ex = std::make_shared<ExportOptions>();
  c = zones->add_subcommand("export", "the normalised zones as GeoJSON (ellipsoidal and AMSL limits)");
  c->add_option("files", ex->files, "zone files")->required();
  c->add_option("--format", ex->format, "auto (default), ed269, ed318, geojson or qgc");
  c->add_option("--to", ex->to, "output format: geojson");
  c->add_option("--output,-o", ex->output, "output file (default stdout)");
  c->add_option("--terrain", ex->terrain, "terrain raster for AGL limits; default flat at 0 m AMSL");
  c->add_flag("--repair", ex->repair, "repair what can be repaired before export");
  c->callback([ex] { runExport(*ex); });
}

}  // namespace skylane::cli
