#pragma once
/// \file
/// \brief The zone model: a UAS geographical zone as EUROCAE ED-269 / ED-318 define it
/// (identifier, restriction, reasons, message, volumes, time applicability), whatever file it
/// came from.
///
/// Coordinates are WGS-84 latitude/longitude in radians. A vertical limit keeps the reference
/// the file gave (AGL, AMSL, WGS-84 ellipsoid) in metres; airspace/vertical.hpp resolves it
/// to an ellipsoidal height with the geoid and the terrain. Feet and flight levels are
/// converted to metres at load.

#include "maps/time.hpp"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::airspace {

/// \brief What a zone means for a flight (ED-269 `restriction`, ED-318 `type`).
enum class Restriction { kProhibited, kReqAuthorisation, kConditional, kNoRestriction };

/// \brief The vertical reference of a limit (ED-269/ED-318 CodeVerticalReferenceType).
enum class VerticalReference { kAgl, kAmsl, kWgs84 };

/// \brief "PROHIBITED", "REQ_AUTHORISATION", "CONDITIONAL", "NO_RESTRICTION".
[[nodiscard]] std::string_view restrictionName(Restriction r);
/// \brief Parses ED-269 and ED-318 spellings (REQ_AUTHORISATION and REQ_AUTHORIZATION).
[[nodiscard]] std::optional<Restriction> parseRestriction(std::string_view text);
/// \brief What a zone is called in reports and exports: "KEEP_IN" for a keep-in zone, else
/// restrictionName of its restriction.
struct Zone;
[[nodiscard]] std::string_view restrictionLabel(const Zone& z);
/// \brief "AGL", "AMSL", "WGS84".
[[nodiscard]] std::string_view referenceName(VerticalReference r);

/// \brief Metres per international foot.
inline constexpr double kMetresPerFoot = 0.3048;

/// \brief A latitude/longitude pair [rad].
struct LatLon {
  double lat_rad = 0.0;
  double lon_rad = 0.0;
};

/// \brief A floor or a ceiling.
struct VerticalLimit {
  double value_m = 0.0;  ///< metres above the reference (converted from feet at load)
  VerticalReference reference = VerticalReference::kAgl;
  /// No bound: a ceiling at +∞ (ED-269 null, ED-318 99999), a floor at −∞ (no floor given:
  /// the zone reaches down to and below the surface).
  bool unlimited = false;
  std::string as_given;    ///< the file's text, e.g. "250 FT AGL", for reports
};

/// \brief A horizontal outline: a polygon ring or a circle.
struct Outline {
  enum class Kind { kPolygon, kCircle };
  Kind kind = Kind::kPolygon;
  /// Polygon: counter-clockwise seen from above, no repeated closing vertex, longitudes
  /// continuous (a ring across the antimeridian may run past ±π).
  std::vector<LatLon> ring;
  LatLon centre;          ///< circle
  double radius_m = 0.0;  ///< circle, on the ellipsoid surface
};

/// \brief One volume of a zone: an outline extruded between a floor and a ceiling.
struct Volume {
  Outline outline;
  VerticalLimit lower;
  VerticalLimit upper;
};

/// \brief A daily period of a weekly schedule. Times are seconds from the start of the local
/// day written in the file, already shifted to UTC (so they may be < 0 or ≥ 86400); a period
/// whose end is not after its start runs past midnight into the next day.
struct DailyPeriod {
  unsigned days = 0x7f;   ///< bit d set ⇔ active on weekday d (0 = Monday … 6 = Sunday)
  double start_s = 0.0;   ///< inclusive
  double end_s = 86400.0; ///< exclusive
  bool approximated = false;  ///< a sunrise/sunset event replaced by the whole day (safe side)
};

/// \brief One applicability entry; a zone is active when any entry is.
struct Applicability {
  bool permanent = true;
  std::optional<maps::GpsTime> start;  ///< inclusive
  std::optional<maps::GpsTime> end;    ///< exclusive
  std::vector<DailyPeriod> schedule;   ///< empty: all day, every day
};

/// \brief A UAS geographical zone.
struct Zone {
  std::string identifier;
  std::string name;
  std::string country;
  Restriction restriction = Restriction::kProhibited;
  std::vector<std::string> reasons;
  std::string message;
  std::vector<Volume> volumes;
  std::vector<Applicability> applicability;  ///< empty: permanent
  /// A keep-in zone (a QGroundControl inclusion fence, a GeoJSON zone with restriction KEEP_IN
  /// or keep_in: true): the vehicle must stay inside it (inside the union of the active ones,
  /// geofence/keep_in.hpp); `restriction` then means nothing.
  bool keep_in = false;
  std::string source;   ///< the file it came from
  std::string feature;  ///< where in the file, e.g. "UASZoneList[0]"
  std::vector<std::string> notes;  ///< normalisations and repairs done at load, for reports
};

/// \brief "file: feature (identifier)" for messages.
[[nodiscard]] std::string describe(const Zone& z);

}  // namespace skylane::airspace
