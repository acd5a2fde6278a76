#pragma once
/// \file
/// \brief When a zone applies: at an instant, and over an interval (the time a vehicle spends
/// near it).
///
/// Rules (ED-269 §4.3 / ED-318 TimePeriod): a zone with no applicability entry is permanent;
/// an entry applies from `start` (inclusive) to `end` (exclusive), on the days and between
/// the times of its schedule (start inclusive, end exclusive); a daily period whose end is
/// not after its start runs across midnight into the next day; the weekday named is the day
/// the period starts, in the time zone its times are written in. A zone is active when any
/// of its entries is.

#include "airspace/zone.hpp"

#include <optional>
#include <string>

namespace skylane::airspace {

/// \brief True when the entry applies at `t`.
[[nodiscard]] bool isActive(const Applicability& a, const maps::GpsTime& t);
/// \brief True when the entry applies at some instant of [t0, t1) (at t0 when t1 ≤ t0).
[[nodiscard]] bool isActiveDuring(const Applicability& a, const maps::GpsTime& t0, const maps::GpsTime& t1);

/// \brief True when the zone applies at `t`.
[[nodiscard]] bool isActive(const Zone& z, const maps::GpsTime& t);
/// \brief True when the zone applies at some instant of [t0, t1) (at t0 when t1 ≤ t0).
[[nodiscard]] bool isActiveDuring(const Zone& z, const maps::GpsTime& t0, const maps::GpsTime& t1);

/// \brief True when the zone applies at every instant: it has no entry, or an entry that is
/// permanent (no date range) with no schedule. Then isActive and isActiveDuring are true at any
/// time, so a checker may skip asking them.
[[nodiscard]] bool isAlwaysActive(const Zone& z);

/// \brief Parses a time of day "HH:MM[:SS[.fff]]" followed by "Z" or "±HH:MM" into seconds
/// after the local midnight expressed in UTC (so "01:00+02:00" → −3600). "24:00" is the end of
/// the day. nullopt when the text is not such a time.
[[nodiscard]] std::optional<double> parseTimeOfDay(const std::string& text);

/// \brief The ED-269/ED-318 code of weekday d (0 = MON … 6 = SUN).
[[nodiscard]] const char* weekdayName(unsigned d);
/// \brief Weekday code (MON … SUN, ANY) → bit mask of DailyPeriod::days; nullopt otherwise.
[[nodiscard]] std::optional<unsigned> weekdayMask(const std::string& code);

}  // namespace skylane::airspace
