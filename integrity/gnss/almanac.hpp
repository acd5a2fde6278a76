#pragma once
/// \file
/// \brief YUMA and SEM almanacs (IS-GPS-200 §20.3.3.5.1.2 contents; file layouts as published
/// by the US Coast Guard Navigation Center and used by MAAST).

#include "integrity/gnss/ephemeris.hpp"
#include "maps/text_file.hpp"

#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief One almanac entry. `week_field` is the week as written (often modulo 1024 or 256).
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

/// \brief Resolves a truncated almanac week (modulo 256 when < 256, modulo 1024 when < 1024,
/// full otherwise) to the full week that puts t_oa closest to `near`.
[[nodiscard]] GpsTime resolveAlmanacEpoch(int week_field, double toa_s, const GpsTime& near);

/// \brief Satellite position and clock from an almanac at time t; t_oa's week is resolved
/// near t. Clock: af0 + af1·t_k + relativistic term.
[[nodiscard]] SatelliteState almanacState(const AlmanacRecord& rec, const GpsTime& t);

/// \brief Reads a whole file (maps/text_file.hpp).
using maps::readTextFile;

}  // namespace skylane::integrity
