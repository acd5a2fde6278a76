#pragma once
/// \file
/// \brief GPS time for the GNSS code: the time scale lives in maps/time.hpp (the lowest module,
/// so that airspace applicability and the integrity code share one calendar and one RFC 3339
/// reader); these declarations keep the integrity namespace's spelling.

#include "maps/time.hpp"

namespace skylane::integrity {

using maps::CalendarTime;
using maps::GpsTime;
using maps::kSecondsPerDay;
using maps::kSecondsPerWeek;
using maps::calendarFromGps;
using maps::daysFromCivil;
using maps::formatRfc3339;
using maps::gpsFromCalendar;
using maps::gpsFromUtc;
using maps::isValidCalendar;
using maps::leapSecondsAtGps;
using maps::parseDuration;
using maps::parseRfc3339;
using maps::utcFromGps;

}  // namespace skylane::integrity
