#pragma once
/// \file
/// \brief The one height a point query takes — `--alt-amsl`, `--height-agl` or `--h-ell` —
/// and the WGS-84 ellipsoidal height it gives, checked (`zones at`, `skymask`).

#include "maps/geoid.hpp"
#include "maps/terrain.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace skylane::cli {

/// \brief The height options as given (exactly one must be).
struct HeightOptions {
  std::optional<double> alt_amsl_m, height_agl_m, h_ell_m;
};

/// \brief Adds --alt-amsl, --height-agl (described by `agl_help`) and --h-ell to the command.
void addHeightOptions(CLI::App& command, HeightOptions& options, const std::string& agl_help);

/// \brief The ellipsoidal height at (lat, lon) [rad] that the one given option means: AMSL
/// through the geoid, AGL over `ground` (whose source, for errors, is `ground_source`).
/// \throws maps::ParseError naming the option and its value when none or several are given,
/// when the value is not finite, when the ground does not cover the point (AGL), or when the
/// height lies outside the heights skylane models (geofence::kSceneFloor_h_ell_m …
/// kSceneCeiling_h_ell_m).
[[nodiscard]] double ellipsoidalHeight(const HeightOptions& options, double lat_rad, double lon_rad, const maps::Terrain& ground,
                                       const std::string& ground_source, const maps::Geoid& geoid);

}  // namespace skylane::cli
