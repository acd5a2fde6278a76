#pragma once
/// \file
/// \brief RINEX navigation files: 2.10/2.11 GPS ('N') and 3.0x GPS LNAV + Galileo (mixed 'M',
/// 'G' or 'E'), after the RINEX 2.11 (Gurtner & Estey 2007) and 3.05 (IGS/RTCM 2020) specs.
/// Records of other systems in a mixed file are skipped (counted in `skipped_records`).

#include "integrity/gnss/ephemeris.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief GPS broadcast ionosphere (Klobuchar) coefficients α0..α3, β0..β3.
struct KlobucharParams {
  std::array<double, 4> alpha{};
  std::array<double, 4> beta{};
};

/// \brief Everything a navigation file provides.
struct NavigationData {
  double version = 0.0;
  std::vector<BroadcastEphemeris> ephemerides;
  std::optional<KlobucharParams> klobuchar;
  std::optional<std::array<double, 3>> nequick_ai;  ///< Galileo ai0, ai1, ai2
  std::optional<int> leap_seconds;
  int skipped_records = 0;  ///< records of systems skylane does not use (GLONASS, BeiDou, …)

  /// \brief Appends another file's records (headers: the first value found wins).
  void merge(const NavigationData& other);
};

/// \brief Parses the text of a RINEX 2.1x or 3.0x navigation file. Throws ParseError naming
/// the source, the line and the field on malformed input.
[[nodiscard]] NavigationData parseRinexNav(const std::string& text, const std::string& source);
/// \brief Reads and parses a navigation file.
[[nodiscard]] NavigationData loadRinexNav(const std::string& path);

/// \brief The ephemeris to use for a satellite at time t: healthy, toe within the validity
/// window (GPS 2 h, Galileo 2 h either side, as RTKLIB's MAXDTOE), closest toe. nullptr if none.
[[nodiscard]] const BroadcastEphemeris* selectEphemeris(const NavigationData& nav, const SatId& sat,
                                                        const GpsTime& t);

}  // namespace skylane::integrity
