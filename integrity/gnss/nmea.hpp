#pragma once
/// \file
/// \brief NMEA 0183 (v4.11) receiver output for live tracking: GGA (fix), GST (pseudorange
/// error statistics), GBS (the receiver's own RAIM fault detection), RMC and ZDA (the date),
/// with the checksum checked, and the sentences of one epoch gathered into a fix.
///
/// Sentence layouts (NMEA 0183 v4.11 §6.3; field numbers after the address field):
///   GGA  1 UTC hhmmss.ss, 2–3 latitude ddmm.mmmm N/S, 4–5 longitude dddmm.mmmm E/W, 6 quality,
///        7 satellites used, 8 HDOP, 9–10 altitude above the geoid, M, 11–12 geoid separation, M
///   GST  1 UTC, 2 RMS of the pseudorange residuals, 3–5 error ellipse semi-major, semi-minor [m]
///        and orientation [deg], 6–8 σ of latitude, longitude, altitude [m]
///   GBS  1 UTC, 2–4 expected error of latitude, longitude, altitude [m] (RAIM), 5 id of the most
///        likely failed satellite, 6 probability of missed detection, 7 estimated bias [m],
///        8 σ of that bias [m]
///   RMC  1 UTC, 2 status A/V, …, 9 date ddmmyy;  ZDA 1 UTC, 2 day, 3 month, 4 year
/// Any two-letter talker (GP, GN, GL, GA, GB, …) is accepted.

#include "integrity/gnss/gnss_time.hpp"

#include <optional>
#include <string>
#include <variant>

namespace skylane::integrity {

/// \brief UTC time of day [s] as the receiver writes it (hhmmss.ss).
struct NmeaTimeOfDay {
  double seconds = 0.0;  ///< 0 ≤ s < 86 401 (a leap second may read 23:59:60)
};

/// \brief GGA: the position fix.
struct NmeaGga {
  NmeaTimeOfDay utc;
  std::optional<double> lat_rad, lon_rad;  ///< empty when the receiver has no fix
  int quality = 0;       ///< 0 invalid, 1 GNSS, 2 DGNSS, 4 RTK fixed, 5 RTK float, 6 dead reckoning, …
  int satellites = 0;
  std::optional<double> hdop;
  std::optional<double> alt_msl_m;        ///< above the geoid
  std::optional<double> geoid_separation_m;  ///< geoid above the ellipsoid
};

/// \brief GST: error statistics of the fix (1σ) [m].
struct NmeaGst {
  NmeaTimeOfDay utc;
  std::optional<double> rms_m, semi_major_m, semi_minor_m, orientation_deg;
  std::optional<double> sigma_lat_m, sigma_lon_m, sigma_alt_m;
};

/// \brief GBS: the receiver's RAIM outcome [m].
struct NmeaGbs {
  NmeaTimeOfDay utc;
  std::optional<double> err_lat_m, err_lon_m, err_alt_m;
  std::optional<int> failed_satellite;
  std::optional<double> p_missed_detection;
  std::optional<double> bias_m, bias_sigma_m;
};

/// \brief RMC or ZDA: the date (and the time of day).
struct NmeaDate {
  NmeaTimeOfDay utc;
  int year = 0, month = 0, day = 0;
};

/// \brief A sentence skylane does not use (its type, e.g. "GSV"), kept so a stream can skip it.
struct NmeaOther {
  std::string type;
};

/// \brief One parsed sentence.
using NmeaSentence = std::variant<NmeaGga, NmeaGst, NmeaGbs, NmeaDate, NmeaOther>;

/// \brief Parses one line ("$GNGGA,…*hh", with or without the line end).
/// \throws ParseError naming `source` (e.g. "fixes.nmea:12"), the field (e.g. "GGA field 2
/// (latitude)"), the text and what was expected; a wrong or missing checksum is an error.
[[nodiscard]] NmeaSentence parseNmeaSentence(const std::string& line, const std::string& source);

/// \brief One epoch's fix from GGA (+ GST, GBS of the same time of day).
struct NmeaFix {
  GpsTime time;
  double lat_rad = 0.0, lon_rad = 0.0;
  double h_ell_m = 0.0;  ///< altitude + geoid separation (the receiver's own geoid)
  int quality = 0;
  int satellites = 0;
  std::optional<double> hdop;
  std::optional<NmeaGst> gst;
  std::optional<NmeaGbs> gbs;
};

/// \brief Gathers the sentences of a stream into fixes. A GGA starts an epoch; GST and GBS with
/// the same time of day join it; the epoch is released when a sentence of another time of day
/// arrives, or by flush(). The date comes from the last RMC/ZDA, else from `default_date`.
class NmeaEpochAssembler {
 public:
  explicit NmeaEpochAssembler(std::optional<NmeaDate> default_date = std::nullopt);
  /// \brief Adds a sentence; returns the fix of the previous epoch when this one closes it.
  /// \throws std::invalid_argument when a fix needs a date and none is known yet.
  std::optional<NmeaFix> add(const NmeaSentence& s);
  /// \brief Releases the epoch in progress, if any.
  std::optional<NmeaFix> flush();

 private:
  std::optional<NmeaFix> release();
  std::optional<NmeaDate> date_;
  std::optional<NmeaGga> gga_;
  std::optional<NmeaGst> gst_;
  std::optional<NmeaGbs> gbs_;
};

}  // namespace skylane::integrity
