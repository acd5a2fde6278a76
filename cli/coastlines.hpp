#pragma once
/// \file
/// \brief World coastlines for the map plots: GSHHG 2.3.7 crude shorelines (Wessel & Smith,
/// LGPL-3.0-or-later), made by cli/data/make_coastlines.sh and embedded at build time.

#include <utility>
#include <vector>

namespace skylane::cli {

/// \brief One coastline as (longitude, latitude) in degrees; open at the antimeridian.
using Coastline = std::vector<std::pair<double, double>>;

/// \brief The embedded coastlines, parsed once.
[[nodiscard]] const std::vector<Coastline>& worldCoastlines();

}  // namespace skylane::cli
