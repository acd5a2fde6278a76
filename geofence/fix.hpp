#pragma once
/// \file
/// \brief A position fix with its protection levels, as one JSON object (a `--fix` argument or
/// one line of a JSON-lines stream; README "Fence check").

#include "maps/time.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace skylane::geofence {

/// \brief {"time", "lat", "lon", "h_ell_m", "hpl_m", "vpl_m"} and optionally "id" and "until".
struct Fix {
  nlohmann::json id;       ///< null when absent; echoed in the output
  maps::GpsTime t0;        ///< "time"
  maps::GpsTime t1;        ///< "until" (the end of an interval), else t0
  double lat_rad = 0, lon_rad = 0, h_ell_m = 0;
  double hpl_m = 0, vpl_m = 0;
};

/// \brief Parses one fix; `source` names it in errors (the option, or "file:line").
/// \throws maps::ParseError naming the field, the value and what was expected (unknown fields,
/// a time that is not RFC 3339, latitude/longitude out of range, a negative protection level,
/// "until" before "time").
[[nodiscard]] Fix parseFix(const nlohmann::json& doc, const std::string& source);

}  // namespace skylane::geofence
