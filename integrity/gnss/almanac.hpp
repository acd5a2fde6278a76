#pragma once
/// \file
/// \brief YUMA and SEM almanacs (IS-GPS-200 §20.3.3.5.1.2 contents; file layouts as published
/// by the US Coast Guard Navigation Center and used by MAAST).

#include "integrity/gnss/ephemeris.hpp"
#include "maps/text_file.hpp"

#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief One almanac entry. `week_field` is the week as written: modulo 1024 in both formats
/// (see resolveAlmanacEpoch), or a full week from producers that write one.
struct AlmanacRecord {
  SatId sat;
  int health = 0;
  KeplerOrbit orbit;  ///< toe = t_oa with the week as written (see resolveAlmanacWeek)
  int week_field = 0;
  double af0_s = 0.0;
  double af1_sps = 0.0;
  int source_line = 0;
};

/// \brief How the constellation of each record is decided.
enum class AlmanacSystem {
  kAuto,     ///< header text "GAL"/"SVID" or ID ≥ 75 (MAAST convention, PRN = ID − 74) → Galileo
  kGps,
  kGalileo,
};

/// \brief Parses a YUMA almanac. Throws ParseError (file, line, field) on malformed input.
[[nodiscard]] std::vector<AlmanacRecord> parseYuma(const std::string& text, const std::string& source,
                                                   AlmanacSystem system = AlmanacSystem::kAuto);
/// \brief Parses a SEM almanac (semicircle units; inclination as offset from 0.30 semicircles).
[[nodiscard]] std::vector<AlmanacRecord> parseSem(const std::string& text, const std::string& source,
                                                  AlmanacSystem system = AlmanacSystem::kAuto);
/// \brief Reads a file and parses it as YUMA or SEM (detected from the first line).
[[nodiscard]] std::vector<AlmanacRecord> loadAlmanac(const std::string& path,
                                                     AlmanacSystem system = AlmanacSystem::kAuto);

/// \brief Weeks of a GPS week-number roll-over: SEM and YUMA write the week modulo 1024.
inline constexpr int kAlmanacWeekModulus = 1024;

/// \brief The full GPS week of an almanac's t_oa: the week as written plus the number of
/// 1024-week roll-overs that puts t_oa nearest to `near` (the mission's time: the departure, or
/// --start), never before the week as written.
///
/// Both almanac formats define the week modulo 1024: the SEM "GPS Week Number" (the almanac
/// reference week, range 0 to 1023) and the YUMA "week" (0000–1023), as in the US Coast Guard
/// Navigation Center's format descriptions. A week of 1024 or more is taken as a full week:
/// some producers write one (the Navigation Center's own SEM files in late 1999, receiver
/// vendors' almanacs). No format skylane reads writes the broadcast 8-bit WN_a (modulo 256,
/// IS-GPS-200 §20.3.3.5.1.2), so a small week is never taken as one: SEM week 38 near 2020 is
/// week 2086, and near 2025 still 2086 (5 years away), not 2342.
///
/// The roll-over is 1024 weeks (19.6 years); for `near` more than 512 weeks from every candidate
/// epoch the choice is ambiguous, but any such epoch is far beyond the age limits
/// (integrity/gnss/orbit_age.hpp), so the ambiguity never changes a decision.
[[nodiscard]] GpsTime resolveAlmanacEpoch(int week_field, double toa_s, const GpsTime& near);

/// \brief Satellite position and clock from an almanac at time t; t_oa's week is resolved
/// near t. Clock: af0 + af1·t_k + relativistic term.
[[nodiscard]] SatelliteState almanacState(const AlmanacRecord& rec, const GpsTime& t);

/// \brief Reads a whole file (maps/text_file.hpp).
using maps::readTextFile;

}  // namespace skylane::integrity
