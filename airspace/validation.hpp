#pragma once
/// \file
/// \brief Zone validation and repair (CGAL exact predicates).
///
/// Always normalised, with a note: a repeated closing vertex, consecutive duplicate vertices,
/// clockwise rings (reversed to counter-clockwise), rings crossing the antimeridian (longitudes
/// made continuous). Errors, each naming the file, the zone, the volume and the vertex:
/// fewer than 3 distinct vertices, a self-intersecting ring, a ring around a pole, a floor
/// above its ceiling (same reference). `repair` fixes what can be fixed on the safe side:
/// a self-intersecting ring of a restrictive zone becomes the outer boundary of the area it
/// encloses (a superset: the zone only grows); keep-in zones are never repaired, because
/// growing them would not be safe.

#include "airspace/loaders.hpp"
#include "airspace/zone.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace skylane::airspace {

/// \brief One finding about one zone.
struct ZoneIssue {
  std::size_t zone = 0;  ///< index in the validated list
  int volume = -1;       ///< −1: the zone as a whole
  int vertex = -1;       ///< index in the file's ring, −1: none
  bool error = false;    ///< false: a note (normalisation)
  bool repaired = false; ///< an error that `repair` fixed
  std::string message;   ///< names the file, the zone, the volume and the vertex
  std::string what;      ///< the finding alone, without the location
};

/// \brief Everything validation found.
struct ValidationReport {
  std::vector<ZoneIssue> issues;
  /// \brief True when no error is left unrepaired.
  [[nodiscard]] bool ok() const;
  /// \brief The first unrepaired error (nullptr when ok()).
  [[nodiscard]] const ZoneIssue* firstError() const;
};

/// \brief Validates and normalises `zones` in place (repairing when asked).
[[nodiscard]] ValidationReport validateZones(std::vector<Zone>& zones, bool repair);

/// \brief Reads, parses and validates one zone file; throws maps::ParseError with the first
/// unrepaired error. Normalisations and repairs end up in each Zone::notes.
[[nodiscard]] std::vector<Zone> loadZones(const std::string& path, ZoneFormat format = ZoneFormat::kAuto,
                                        bool repair = false);

}  // namespace skylane::airspace
