#pragma once
/// \file
/// \brief How old an orbit file is at the mission's time (the departure, or --start), and the
/// limits past which a prediction from it earns a warning or is refused.
///
/// Almanac age = |t − t_oa|, t_oa's week resolved near t (resolveAlmanacEpoch). Ephemeris age:
/// for each satellite of a navigation file, the distance from t to its nearest t_oe; the file's
/// age is the largest over its satellites (every satellite the file brings must be current).

#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/rinex_nav.hpp"

#include <string>
#include <utility>
#include <vector>

namespace skylane::integrity {

/// \brief What an orbit file holds.
enum class OrbitKind { kAlmanac, kEphemeris };

/// \brief "almanac", "ephemeris".
[[nodiscard]] const char* orbitKindName(OrbitKind kind);

/// \brief Ages past `warning_s` are reported, ages past `error_s` refused [s].
struct OrbitAgeLimits {
  double warning_s = 0.0;
  double error_s = 0.0;
};

/// \brief Almanac: warning beyond 7 days, error beyond 90 days. The GPS control segment uploads
/// a new almanac about daily and a receiver holds one at most days old; an almanac's orbits are
/// a few kilometres off within days and drift further over weeks, and one older than a
/// satellite's station-keeping manoeuvre is wrong for that satellite altogether — the main
/// reason an almanac's useful life is weeks, not months (T. Driver, "How long can you use an
/// almanac?", Inside GNSS, GNSS Solutions, Nov./Dec. 2008). An almanac more than a week from
/// the flight is not the current one (worth a warning); beyond 90 days the predicted geometry
/// (which satellites, where) is not the flight's, and the approval is refused.
inline constexpr OrbitAgeLimits kAlmanacAgeLimits{7.0 * 86400.0, 90.0 * 86400.0};

/// \brief Broadcast ephemeris: warning beyond 4 h, error beyond 7 days. An ephemeris is fitted
/// over 4 hours round t_oe (IS-GPS-200, curve fit interval flag 0) and skylane uses it within
/// 2 h of t_oe (selectEphemeris); a departure 4 h from every t_oe has no ephemeris for those
/// satellites (the almanac, if any, stands in). A file a week away is another day's
/// constellation: the wrong file.
inline constexpr OrbitAgeLimits kEphemerisAgeLimits{4.0 * 3600.0, 7.0 * 86400.0};

/// \brief The epochs one orbit file provides: per record, the satellite and t_oa with the
/// week as written (almanac) or t_oe as a full GPS time (ephemeris).
struct OrbitFileEpochs {
  std::string file;
  OrbitKind kind = OrbitKind::kAlmanac;
  std::vector<std::pair<SatId, GpsTime>> epochs;
};

/// \brief The epochs of an almanac's records.
[[nodiscard]] OrbitFileEpochs almanacEpochs(const std::string& file, const std::vector<AlmanacRecord>& records);
/// \brief The epochs of a navigation file's ephemerides.
[[nodiscard]] OrbitFileEpochs ephemerisEpochs(const std::string& file, const NavigationData& nav);

/// \brief How an age compares with its limits.
enum class AgeVerdict { kCurrent, kWarning, kError };

/// \brief One file's age at time t.
struct OrbitFileAge {
  std::string file;
  OrbitKind kind = OrbitKind::kAlmanac;
  GpsTime epoch;        ///< the epoch farthest from t (almanac t_oa resolved near t; t_oe nearest t)
  GpsTime at;           ///< the mission's time the age is measured from
  double age_s = 0.0;   ///< |at − epoch|
  OrbitAgeLimits limits;
  AgeVerdict verdict = AgeVerdict::kCurrent;
};

/// \brief The file's age at t: almanac max over records of |t − t_oa|; ephemeris max over
/// satellites of the distance to the satellite's nearest t_oe. A file without epochs is current.
[[nodiscard]] OrbitFileAge orbitFileAge(const OrbitFileEpochs& file, const GpsTime& t);

/// \brief The epoch as RFC 3339 and GPS week: "2020-01-04T19:56:30Z (GPS week 2086, 503808 s)".
[[nodiscard]] std::string describeEpoch(const OrbitFileAge& age);

/// \brief One sentence naming the file, its kind, its epoch, the mission's time (`time_name`,
/// e.g. "the departure" or "--start"), the age and the limit passed: "alm.txt: the almanac's
/// t_oa 2020-01-04T19:56:30Z (GPS week 2086, 503808 s) is 10.2 days from the departure
/// 2020-01-15T00:00:00Z, beyond the 7.0 days warning limit".
[[nodiscard]] std::string describeAge(const OrbitFileAge& age, const std::string& time_name);

/// \brief Past the error limit: throws maps::ParseError naming the file, the epoch, the
/// mission's time, the limit and the age. Past the warning limit: returns describeAge's
/// sentence; current: "".
[[nodiscard]] std::string requireUsableAge(const OrbitFileAge& age, const std::string& time_name);

}  // namespace skylane::integrity
