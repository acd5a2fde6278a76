#include "cli/skymask_commands.hpp"

#include "cli/height_options.hpp"
#include "cli/json_numbers.hpp"
#include "cli/svg_plot.hpp"
#include "maps/buildings.hpp"
#include "maps/geoid.hpp"
#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

namespace skylane::cli {
namespace {

using maps::ParseError;
using nlohmann::json;

struct SkyMaskCliOptions {
  double lat_deg = NAN, lon_deg = NAN;
  HeightOptions height;
  std::string buildings;
  std::string terrain;
  std::optional<double> ground_amsl_m;
  double bin_deg = 1.0;
  double terrain_range_m = 10000.0;
  double metres_per_level = maps::kMetresPerLevel;
  std::optional<double> default_height_m;
  std::string svg;
};

void runSkyMask(const SkyMaskCliOptions& o) {
  if (!(std::abs(o.lat_deg) <= 90.0)) throw ParseError("--lat", 0, "--lat", std::to_string(o.lat_deg), "a latitude in [-90, 90]");
  if (!(std::abs(o.lon_deg) <= 180.0)) throw ParseError("--lon", 0, "--lon", std::to_string(o.lon_deg), "a longitude in [-180, 180]");
  if (o.buildings.empty() && o.terrain.empty() && !o.ground_amsl_m) {
    throw ParseError("--buildings", 0, "--buildings|--terrain|--ground-amsl", "", "something that blocks the sky");
  }
  const double bins = 360.0 / o.bin_deg;
  if (!(bins >= 1.0 && bins <= 36000.0) || std::abs(bins - std::round(bins)) > 1e-9 * bins) {
    throw ParseError("--bin-deg", 0, "--bin-deg", std::to_string(o.bin_deg), "a bin width that divides 360° (e.g. 0.5, 1, 2, 5)");
  }
  if (!(o.terrain_range_m > 0.0 && o.terrain_range_m <= 200000.0)) {
    throw ParseError("--terrain-range", 0, "--terrain-range", std::to_string(o.terrain_range_m), "a range in (0, 200000] m");
  }
  const maps::Terrain ground = groundModel(o.terrain, o.ground_amsl_m);
  const maps::Geoid& geoid = maps::Geoid::egm96();
  const double lat = maps::deg2rad(o.lat_deg), lon = maps::deg2rad(o.lon_deg);
  const double h_ell = ellipsoidalHeight(o.height, lat, lon, ground, o.terrain, geoid);
  maps::SkyMaskOptions opt;
  opt.bin_width_rad = maps::deg2rad(o.bin_deg);
  opt.terrain_max_range_m = o.terrain_range_m;
  maps::BuildingOptions bopt;
  bopt.metres_per_level = o.metres_per_level;
  bopt.default_height_m = o.default_height_m;
  std::size_t count = 0;
  const maps::Geodetic place{lat, lon, h_ell};
  const maps::SkyMask mask = skyMaskAt(place, o.buildings, ground, !o.terrain.empty() || o.ground_amsl_m.has_value(), opt, bopt, &count);

  json out;
  out["position"] = {{"lat_deg", o.lat_deg}, {"lon_deg", o.lon_deg}, {"h_ell_m", roundToMm(h_ell)},
                     {"alt_amsl_m", roundToMm(geoid.amslFromEllipsoidal_m(lat, lon, h_ell))}};
  out["buildings"] = {{"file", o.buildings}, {"count", count}};
  out["terrain"] = ground.describe();
  out["terrain_horizon"] = !o.terrain.empty() || o.ground_amsl_m.has_value();
  out["bin_deg"] = o.bin_deg;
  out["open_sky_deg"] = maps::rad2deg(maps::kOpenSky_rad);
  json az = json::array(), blocked = json::array();
  std::vector<double> blocked_deg;
  double highest = -90.0;
  for (int k = 0; k < mask.bins(); ++k) {
    az.push_back(roundToMm(k * o.bin_deg));
    blocked_deg.push_back(maps::rad2deg(mask.binBlocked_rad(k)));
    blocked.push_back(roundToMm(blocked_deg.back()));
    highest = std::max(highest, blocked_deg.back());
  }
  out["azimuth_from_deg"] = az;
  out["blocked_elevation_deg"] = blocked;
  out["max_blocked_elevation_deg"] = roundToMm(highest);
  std::cout << out.dump() << "\n";
  if (!o.svg.empty()) {
    char title[160];
    std::snprintf(title, sizeof title, "sky mask at %.6f°, %.6f°, %.1f m (ellipsoidal)", o.lat_deg, o.lon_deg, h_ell);
    const std::string footer = std::to_string(count) + " buildings from " + (o.buildings.empty() ? "(none)" : o.buildings) +
                               "; bins of " + json(o.bin_deg).dump() + "°; shaded: blocked";
    maps::writeFileAtomically(o.svg, renderSkyPlotSvg(title, blocked_deg, o.bin_deg, footer), "--svg");
  }
}

}  // namespace

maps::Terrain groundModel(const std::string& terrain_path, std::optional<double> ground_amsl_m) {
  if (!terrain_path.empty()) return maps::Terrain::fromRaster(terrain_path);
  const double alt = ground_amsl_m.value_or(0.0);
  if (!std::isfinite(alt)) throw ParseError("--ground-amsl", 0, "--ground-amsl", std::to_string(alt), "a finite altitude");
  return maps::Terrain::flat(alt);
}

maps::SkyMask skyMaskAt(const maps::Geodetic& place, const std::string& buildings_path, const maps::Terrain& ground,
                        bool with_terrain, const maps::SkyMaskOptions& options,
                        const maps::BuildingOptions& building_options, std::size_t* building_count) {
  std::unique_ptr<maps::BuildingIndex> index;
  if (!buildings_path.empty()) {
    const std::vector<maps::Building> buildings = maps::loadBuildings(buildings_path, ground, building_options);
    index = std::make_unique<maps::BuildingIndex>(buildings, place);
    if (building_count) *building_count = buildings.size();
  }
  return maps::computeSkyMask(place, index.get(), with_terrain ? &ground : nullptr, options);
}

void addSkyMaskCommands(CLI::App& app) {
  auto o = std::make_shared<SkyMaskCliOptions>();
  CLI::App* c = app.add_subcommand("skymask", "the elevation blocked by buildings and terrain in every azimuth bin, as JSON");
  c->add_option("--lat", o->lat_deg, "latitude [deg]")->required();
  c->add_option("--lon", o->lon_deg, "longitude [deg]")->required();
  addHeightOptions(*c, o->height, "height above the ground (--terrain / --ground-amsl) [m]");
  c->add_option("--buildings", o->buildings, "GeoJSON buildings and obstacles (README: Buildings and obstacles)");
  c->add_option("--terrain", o->terrain, "terrain raster: ground under the buildings and the terrain horizon");
  c->add_option("--ground-amsl", o->ground_amsl_m, "flat ground at this altitude AMSL [m] (without --terrain; default 0, and then no terrain horizon)");
  c->add_option("--bin-deg", o->bin_deg, "azimuth bin width [deg], dividing 360 (default 1)");
  c->add_option("--terrain-range", o->terrain_range_m, "how far the terrain is looked at [m] (default 10000)");
  c->add_option("--metres-per-level", o->metres_per_level, "metres per building level (default 3)");
  c->add_option("--default-height", o->default_height_m, "height of buildings that give none [m] (default: an error)");
  c->add_option("--svg", o->svg, "write a polar sky plot of the mask");
  c->callback([o] { runSkyMask(*o); });
}

}  // namespace skylane::cli
