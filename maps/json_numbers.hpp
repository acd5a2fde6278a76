#pragma once
/// \file
/// \brief The one rounding rule of every JSON output (docs/method.md §1.3): lengths to the
/// millimetre, angles in degrees to 1e-8° (about 1 mm on the ground), times to the millisecond,
/// and a non-finite length (an unlimited floor or ceiling, a PL not computed) as null.

#include "maps/geodesy.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace skylane::maps {

/// \brief v rounded to the millimetre [m].
[[nodiscard]] inline double roundToMm(double v) { return std::round(v * 1e3) / 1e3; }

/// \brief An angle [rad] in degrees rounded to 1e-8° (≈ 1 mm of latitude).
[[nodiscard]] inline double roundToDeg8(double rad) { return std::round(rad2deg(rad) * 1e8) / 1e8; }

/// \brief roundToMm(v) as JSON, or null when v is not finite.
[[nodiscard]] inline nlohmann::json metresOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(roundToMm(v)) : nlohmann::json(nullptr);
}

}  // namespace skylane::maps
