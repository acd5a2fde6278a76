#pragma once
/// \file
/// \brief Zone loaders: EUROCAE ED-269 JSON, ED-318 GeoJSON, plain GeoJSON (RFC 7946) and
/// QGroundControl `.plan` geofences.
///
/// Structural errors (a missing or mistyped field, a coordinate out of range, an unknown
/// restriction or reference) raise maps::ParseError naming the file, the feature (path and
/// identifier) and the field. Geometric problems (too few vertices, self-intersection, floor
/// above ceiling) are the validator's business (airspace/validation.hpp): loadZones runs it.
///
/// Format notes (what the loaders accept, beyond the standards' letter, from real files):
/// - ED-269: the `UASZoneList` and the `features` wrappers; limits as numbers, numeric strings
///   ("0") or null (ceiling: unlimited; floor: none); `schedule` or `dailyPeriod`; empty day
///   lists and null times mean every day / the whole day; circle radius in `uomDimensions`.
/// - ED-318: `layer` {upper, upperReference, lower, lowerReference, uom "m"|"ft"} inside each
///   geometry (99999 = unlimited); Polygon, MultiPolygon, Point + `extent` {subType "Circle",
///   radius [m]}, GeometryCollection; `limitedApplicability`; texts as [{text, lang}] (en-GB,
///   else the first); sunrise/sunset events (`startEvent`/`endEvent`) are replaced by the
///   whole day, on the safe side, with a note.
/// - Plain GeoJSON: see README ("Zone files"): properties identifier|id, name, restriction
///   (default PROHIBITED, noted; KEEP_IN: a keep-in zone, as `keep_in: true` says too), lower/upper (number or null), lower_reference/
///   upper_reference (AGL|AMSL|WGS84, default AMSL), uom (m|ft), start/end (RFC 3339),
///   schedule; circles as Point + radius_m (or Azure's subType "Circle" + radius).
/// - QGroundControl: `geoFence.polygons[]` ({inclusion, polygon [[lat, lon], …]}) and
///   `geoFence.circles[]` ({inclusion, circle {center [lat, lon], radius}}); an exclusion
///   fence is a PROHIBITED zone at every height, an inclusion fence a keep-in zone.

#include "airspace/zone.hpp"

#include <nlohmann/json_fwd.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::airspace {

/// \brief A zone file format.
enum class ZoneFormat { kAuto, kEd269, kEd318, kGeoJson, kQgcPlan };

/// \brief "auto", "ed269", "ed318", "geojson", "qgc".
[[nodiscard]] std::string_view formatName(ZoneFormat f);
/// \brief Inverse of formatName.
[[nodiscard]] std::optional<ZoneFormat> parseZoneFormat(std::string_view text);

/// \brief The format a document looks like (ED-269 wrappers, `"fileType": "Plan"`, a GeoJSON
/// FeatureCollection with ED-318 layers/variants, else plain GeoJSON); nullopt when none.
[[nodiscard]] std::optional<ZoneFormat> detectZoneFormat(const nlohmann::json& doc);

/// \brief Parses a zone document (no geometric validation). `source` names it in errors.
[[nodiscard]] std::vector<Zone> parseZones(const nlohmann::json& doc, const std::string& source,
                                           ZoneFormat format = ZoneFormat::kAuto);

/// \brief Reads a zone file (JSON syntax errors name the line) and parses it.
[[nodiscard]] std::vector<Zone> readZoneFile(const std::string& path, ZoneFormat format = ZoneFormat::kAuto);

}  // namespace skylane::airspace
