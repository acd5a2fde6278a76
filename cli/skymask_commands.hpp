#pragma once
/// \file
/// \brief `skylane skymask`: the sky mask at a point from buildings and terrain, as JSON and
/// a polar sky plot.

#include "maps/sky_mask.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace skylane::cli {

/// \brief The ground under buildings and the terrain horizon: a raster when `terrain_path` is
/// given, else flat at `ground_amsl_m`, else flat at 0 m AMSL.
[[nodiscard]] maps::Terrain groundModel(const std::string& terrain_path, std::optional<double> ground_amsl_m);

/// \brief The sky mask at `place` from a buildings file (may be empty) on `ground`; the terrain
/// horizon is included when `with_terrain`. Also used by `integrity predict --buildings`.
[[nodiscard]] maps::SkyMask skyMaskAt(const maps::Geodetic& place, const std::string& buildings_path,
                                      const maps::Terrain& ground, bool with_terrain, const maps::SkyMaskOptions& options,
                                      const maps::BuildingOptions& building_options = {},
                                      std::size_t* building_count = nullptr);

/// \brief Registers `skymask` on `app`.
void addSkyMaskCommands(CLI::App& app);

}  // namespace skylane::cli
