#include "cli/height_options.hpp"

#include "geofence/scene.hpp"
#include "maps/json_numbers.hpp"
#include "maps/parse_error.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

namespace skylane::cli {

namespace {

/// The shortest text that reads back as v.
std::string valueText(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return {text, end};
}

/// A derived height for a message: to the millimetre (roundToMm) where that stays finite.
std::string heightText(double h) { return valueText(std::abs(h) < 1e12 ? maps::roundToMm(h) : h); }

}  // namespace

void addHeightOptions(CLI::App& command, HeightOptions& options, const std::string& agl_help) {
  command.add_option("--alt-amsl", options.alt_amsl_m, "altitude above mean sea level (EGM96) [m]");
  command.add_option("--height-agl", options.height_agl_m, agl_help);
  command.add_option("--h-ell", options.h_ell_m, "WGS-84 ellipsoidal height [m]");
}

double ellipsoidalHeight(const HeightOptions& o, double lat_rad, double lon_rad, const maps::Terrain& ground,
                         const std::string& ground_source, const maps::Geoid& geoid) {
  const int given = (o.alt_amsl_m ? 1 : 0) + (o.height_agl_m ? 1 : 0) + (o.h_ell_m ? 1 : 0);
  if (given != 1) throw maps::ParseError("--alt-amsl", 0, "--alt-amsl|--height-agl|--h-ell", "", "exactly one height");
  const char* option = o.alt_amsl_m ? "--alt-amsl" : (o.height_agl_m ? "--height-agl" : "--h-ell");
  const double value = o.alt_amsl_m ? *o.alt_amsl_m : (o.height_agl_m ? *o.height_agl_m : *o.h_ell_m);
  if (!std::isfinite(value)) throw maps::ParseError(option, 0, option, valueText(value), "a finite height in metres");
  double h_ell = value;
  if (o.alt_amsl_m) h_ell = geoid.ellipsoidalFromAmsl_m(lat_rad, lon_rad, value);
  if (o.height_agl_m) {
    const auto g = ground.heightEllipsoid_m(lat_rad, lon_rad);
    if (!g) throw maps::ParseError(ground_source, 0, option, valueText(value), "a point the terrain model covers");
    h_ell = *g + value;
  }
  if (!(h_ell >= geofence::kSceneFloor_h_ell_m && h_ell <= geofence::kSceneCeiling_h_ell_m)) {
    std::ostringstream expected;
    expected << "a height whose ellipsoidal height lies within " << geofence::kSceneFloor_h_ell_m << " … "
             << geofence::kSceneCeiling_h_ell_m << " m (the heights skylane models";
    if (!o.h_ell_m) expected << "; this one gives " << heightText(h_ell) << " m";
    expected << ")";
    throw maps::ParseError(option, 0, option, valueText(value), expected.str());
  }
  return h_ell;
}

}  // namespace skylane::cli
