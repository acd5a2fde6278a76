#pragma once
/// \file
/// \brief How the commands write metres in JSON: rounded to the millimetre, ±∞ as null.

#include <nlohmann/json.hpp>

#include <cmath>

namespace skylane::cli {

/// \brief v rounded to the millimetre [m].
[[nodiscard]] inline double roundToMm(double v) { return std::round(v * 1e3) / 1e3; }

/// \brief roundToMm(v) as JSON, or null when v is not finite (an unlimited floor or ceiling).
[[nodiscard]] inline nlohmann::json metresOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(roundToMm(v)) : nlohmann::json(nullptr);
}

}  // namespace skylane::cli
