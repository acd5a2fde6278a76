#pragma once
/// \file
/// \brief RINEX observation files 2.10/2.11 and 3.0x (RINEX 2.11 and 3.05 specifications):
/// header essentials and, per epoch and satellite, the observations of the header's types.

#include "integrity/gnss/gnss_time.hpp"
#include "integrity/gnss/satellite_id.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief An observation type in RINEX 3 terms: kind ('C' code, 'L' phase, 'D' Doppler,
/// 'S' signal strength), frequency band (1, 2, 5, 6, 7, 8) and tracking attribute ('C', 'W', …).
struct ObsCode {
  char kind = 'C';
  int band = 1;
  char attribute = 'C';
  std::string as_written;  ///< the code as written in the file ("C1", "P2", "C1C")
};

/// \brief RINEX 2 code ("C1", "P2", "L1") → RINEX 3 meaning (P1 → C1W, C2 → C2X …).
[[nodiscard]] std::optional<ObsCode> obsCodeFromRinex2(const std::string& code);
/// \brief RINEX 3 code ("C1C") → ObsCode.
[[nodiscard]] std::optional<ObsCode> obsCodeFromRinex3(const std::string& code);

/// \brief One satellite's observations at an epoch, aligned with its system's types.
struct SatObservation {
  SatId sat;
  std::vector<double> values;  ///< NaN where blank
};

/// \brief One epoch of observations.
struct ObservationEpoch {
  GpsTime t;        ///< receiver time (GPS time scale)
  int flag = 0;     ///< 0 OK, 1 power failure since previous epoch
  int source_line = 0;
  std::vector<SatObservation> sats;
};

/// \brief A parsed observation file.
struct ObservationData {
  double version = 0.0;
  std::string marker_name;
  std::optional<Eigen::Vector3d> approx_position_ecef;
  double interval_s = 0.0;
  /// \brief Types per constellation (index = Constellation value); empty if the system is absent.
  std::array<std::vector<ObsCode>, kNumConstellations> types;
  std::vector<ObservationEpoch> epochs;
  int skipped_satellites = 0;  ///< observations of systems skylane does not use (SBAS, QZSS …)
};

/// \brief Parses a RINEX observation file's text. Throws ParseError (source, line, field).
[[nodiscard]] ObservationData parseRinexObs(const std::string& text, const std::string& source);
/// \brief Reads and parses an observation file.
[[nodiscard]] ObservationData loadRinexObs(const std::string& path);

/// \brief Index of the first type in `types` with this kind and band whose attribute is one of
/// `attributes` in order of preference (empty = any); -1 when absent.
[[nodiscard]] int findObsType(const std::vector<ObsCode>& types, char kind, int band,
                              const std::string& attributes = "");

}  // namespace skylane::integrity
