#pragma once
/// \file
/// \brief GPS time (week, seconds of week), calendar dates, UTC and the leap-second offset.
///
/// GPS time started 1980-01-06 00:00:00 UTC and carries no leap seconds; UTC = GPS − ΔLS,
/// with ΔLS = 13 s in 2005, 18 s since 2017-01-01 (IERS Bulletin C). Galileo System Time is
/// aligned to GPS time to within tens of nanoseconds and uses the same week length
/// (Galileo OS SIS ICD §5.1.2); its week number is GPS week − 1024.

#include <optional>
#include <string>
#include <string_view>

namespace skylane::maps {

inline constexpr double kSecondsPerWeek = 604800.0;
inline constexpr double kSecondsPerDay = 86400.0;

/// \brief A calendar date-time with fractional seconds, in whichever time scale the caller says.
struct CalendarTime {
  int year = 1980;
  int month = 1;
  int day = 6;
  int hour = 0;
  int minute = 0;
  double second = 0.0;
};

/// \brief GPS time: full week number (not modulo 1024) and seconds of week.
struct GpsTime {
  int week = 0;
  double sow = 0.0;

  /// \brief Seconds since the GPS epoch (1980-01-06 00:00:00 GPS).
  [[nodiscard]] double totalSeconds() const { return week * kSecondsPerWeek + sow; }
  /// \brief From seconds since the GPS epoch.
  /// \throws std::invalid_argument when t_s is not finite or its week does not fit an int.
  [[nodiscard]] static GpsTime fromTotalSeconds(double t_s);
  /// \brief This time plus dt seconds, normalised.
  [[nodiscard]] GpsTime plus(double dt_s) const { return fromTotalSeconds(totalSeconds() + dt_s); }
};

/// \brief t1 − t0 in seconds.
[[nodiscard]] inline double operator-(const GpsTime& t1, const GpsTime& t0) {
  // The weeks are subtracted as doubles: two int weeks far apart would overflow an int.
  return (static_cast<double>(t1.week) - static_cast<double>(t0.week)) * kSecondsPerWeek + (t1.sow - t0.sow);
}

/// \brief True for a real calendar date-time in 1980 … 2200 (month lengths, leap years,
/// seconds < 61 for leap seconds) — the rule every file parser applies to epochs.
[[nodiscard]] bool isValidCalendar(const CalendarTime& c);

/// \brief Calendar date-time read in the GPS time scale → GPS time.
[[nodiscard]] GpsTime gpsFromCalendar(const CalendarTime& c);
/// \brief GPS time → calendar date-time in the GPS time scale.
[[nodiscard]] CalendarTime calendarFromGps(const GpsTime& t);

/// \brief GPS − UTC [s] at the given GPS time (table of IERS leap seconds since 1980).
[[nodiscard]] int leapSecondsAtGps(const GpsTime& t);
/// \brief UTC calendar time → GPS time (adds the leap seconds in force at that instant).
[[nodiscard]] GpsTime gpsFromUtc(const CalendarTime& utc);
/// \brief GPS time → UTC calendar time.
[[nodiscard]] CalendarTime utcFromGps(const GpsTime& t);

/// \brief Parses an RFC 3339 date-time ("2026-11-23T14:00:00Z", "…+01:00", fractional
/// seconds allowed) as UTC and returns GPS time. nullopt when the text is not RFC 3339.
[[nodiscard]] std::optional<GpsTime> parseRfc3339(std::string_view text);
/// \brief GPS time → RFC 3339 UTC string with the given number of fractional digits.
[[nodiscard]] std::string formatRfc3339(const GpsTime& t, int fraction_digits = 0);
/// \brief formatRfc3339 into `out` without allocating (0–6 fractional digits, years 1–9998):
/// the end of the text written (at most kRfc3339MaxChars), or nullptr for any other case, which
/// formatRfc3339 then writes.
[[nodiscard]] char* formatRfc3339To(char* out, const GpsTime& t, int fraction_digits);
/// \brief Longest text formatRfc3339To writes.
inline constexpr int kRfc3339MaxChars = 32;

/// \brief Parses a duration such as "24h", "10m", "30s", "1h30m", "90" (seconds).
/// nullopt when the text is not a positive duration.
[[nodiscard]] std::optional<double> parseDuration(const std::string& text);

/// \brief Days from 1970-01-01 for a proleptic Gregorian date (H. Hinnant, "chrono-compatible
/// low-level date algorithms", days_from_civil).
[[nodiscard]] long daysFromCivil(int y, int m, int d);

}  // namespace skylane::maps
