#include "integrity/gnss/gnss_time.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace skylane::integrity {
namespace {

TEST(GnssTime, GpsEpochIsWeekZero) {
  const GpsTime t = gpsFromCalendar({1980, 1, 6, 0, 0, 0.0});
  EXPECT_EQ(t.week, 0);
  EXPECT_DOUBLE_EQ(t.sow, 0.0);
}

TEST(GnssTime, RinexEpochOfStation3040IsWeek1316Second518400) {
  // 2005-04-02 00:00:00 GPS (first epoch of 30400920.05o) — RTKLIB prints week 1316, tow 518400.
  const GpsTime t = gpsFromCalendar({2005, 4, 2, 0, 0, 0.0});
  EXPECT_EQ(t.week, 1316);
  EXPECT_DOUBLE_EQ(t.sow, 518400.0);
  const CalendarTime c = calendarFromGps(t);
  EXPECT_EQ(c.year, 2005);
  EXPECT_EQ(c.month, 4);
  EXPECT_EQ(c.day, 2);
  EXPECT_EQ(c.hour, 0);
}

TEST(GnssTime, LeapSecondsFollowIersTable) {
  EXPECT_EQ(leapSecondsAtGps(gpsFromCalendar({2005, 4, 2, 0, 0, 0})), 13);  // RINEX header of 30400920.05n
  EXPECT_EQ(leapSecondsAtGps(gpsFromCalendar({2006, 12, 27, 0, 0, 0})), 14);
  EXPECT_EQ(leapSecondsAtGps(gpsFromCalendar({2024, 6, 24, 0, 0, 0})), 18);  // LEAP SECONDS of the RINEX 3 file
  // Across the 2016-12-31 leap second: 2017-01-01T00:00:00 UTC is GPS + 18 s.
  const GpsTime before = gpsFromUtc({2016, 12, 31, 23, 59, 59.0});
  const GpsTime after = gpsFromUtc({2017, 1, 1, 0, 0, 0.0});
  EXPECT_DOUBLE_EQ(after - before, 2.0);  // the inserted second 23:59:60 lies between them
}

TEST(GnssTime, Rfc3339RoundTripAndOffsets) {
  const auto t = parseRfc3339("2020-01-01T00:00:00Z");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->week, 2086);  // GPS week of 2020-01-01
  EXPECT_DOUBLE_EQ(t->sow, 3 * 86400.0 + 18.0);
  EXPECT_EQ(formatRfc3339(*t), "2020-01-01T00:00:00Z");
  const auto t2 = parseRfc3339("2020-01-01T01:30:00+01:30");
  ASSERT_TRUE(t2.has_value());
  EXPECT_DOUBLE_EQ(*t2 - *t, 0.0);
  EXPECT_EQ(formatRfc3339(parseRfc3339("2026-11-23T14:00:00.250Z").value(), 3), "2026-11-23T14:00:00.250Z");
  for (const char* bad : {"", "2020-13-01T00:00:00Z", "2020-01-01", "2020-01-01T00:00:00", "2020-01-01T00:00:00+1",
                          "2020-01-01T25:00:00Z", "yesterday"}) {
    EXPECT_FALSE(parseRfc3339(bad).has_value()) << bad;
  }
}

TEST(GnssTime, Rfc3339FractionsRoundOnceAndCarryIntoTheMinute) {
  const GpsTime t = parseRfc3339("2016-12-31T23:59:59.9996Z").value();
  EXPECT_EQ(formatRfc3339(t, 3), "2017-01-01T00:00:00.000Z");  // rounded up across the year (and a leap second table row)
  EXPECT_EQ(formatRfc3339(t, 4), "2016-12-31T23:59:59.9996Z");
  EXPECT_EQ(formatRfc3339(t, 1), "2017-01-01T00:00:00.0Z");
  EXPECT_EQ(formatRfc3339(parseRfc3339("2005-04-02T00:00:07.05Z").value(), 1), "2005-04-02T00:00:07.1Z");
  EXPECT_EQ(formatRfc3339(parseRfc3339("2005-04-02T09:08:07.123456789Z").value(), 6), "2005-04-02T09:08:07.123457Z");
}

TEST(GnssTime, Rfc3339TextKeptFromTheLastCallIsTheAnswerOfItsOwnText) {
  // The last text read and written is kept per thread: repeats, alternations and a bad text in
  // between each get their own answer.
  const char* a = "2026-11-23T14:00:00.250Z";
  const char* b = "2026-11-23T14:00:01.250Z";
  const GpsTime ta = parseRfc3339(a).value();
  EXPECT_DOUBLE_EQ(parseRfc3339(b).value() - ta, 1.0);
  EXPECT_FALSE(parseRfc3339("2026-11-23T14:00:01.250").has_value());
  EXPECT_DOUBLE_EQ(parseRfc3339(a).value() - ta, 0.0);
  EXPECT_DOUBLE_EQ(parseRfc3339(a).value() - ta, 0.0);
  const GpsTime tb = ta.plus(1.0);
  for (int round = 0; round < 2; ++round) {
    EXPECT_EQ(formatRfc3339(ta, 3), a);
    EXPECT_EQ(formatRfc3339(ta, 3), a);
    EXPECT_EQ(formatRfc3339(ta, 0), "2026-11-23T14:00:00Z");
    EXPECT_EQ(formatRfc3339(tb, 3), b);
  }
}

TEST(GnssTime, DurationsParseUnits) {
  EXPECT_DOUBLE_EQ(parseDuration("24h").value(), 86400.0);
  EXPECT_DOUBLE_EQ(parseDuration("10m").value(), 600.0);
  EXPECT_DOUBLE_EQ(parseDuration("1h30m").value(), 5400.0);
  EXPECT_DOUBLE_EQ(parseDuration("90").value(), 90.0);
  EXPECT_DOUBLE_EQ(parseDuration("1.5s").value(), 1.5);
  for (const char* bad : {"", "0", "-5m", "10x", "h", "1h30", "nan"}) EXPECT_FALSE(parseDuration(bad).has_value()) << bad;
}

TEST(GnssTime, DaysFromCivilMatchesKnownDates) {
  EXPECT_EQ(daysFromCivil(1970, 1, 1), 0);
  EXPECT_EQ(daysFromCivil(1980, 1, 6), 3657);
  EXPECT_EQ(daysFromCivil(2000, 3, 1), 11017);
}

TEST(GnssTime, ATimeThatIsNotOneIsAnErrorNotUndefinedBehaviour) {
  // (issue 23 item 12: −inf reached the int cast of the week)
  const double inf = std::numeric_limits<double>::infinity();
  for (const double t : {inf, -inf, std::nan(""), 1e300, -1e300}) {
    EXPECT_THROW((void)GpsTime::fromTotalSeconds(t), std::invalid_argument) << t;
  }
  // The largest week that fits still converts, and back.
  const GpsTime far = GpsTime::fromTotalSeconds(2.0e9 * 604800.0);
  EXPECT_EQ(far.week, 2000000000);
  EXPECT_DOUBLE_EQ(far.sow, 0.0);
  // Differences of weeks far apart are computed in doubles (an int subtraction would overflow).
  const GpsTime a{2000000000, 0.0}, b{-2000000000, 0.0};
  EXPECT_DOUBLE_EQ(a - b, 4.0e9 * 604800.0);
}

}  // namespace
}  // namespace skylane::integrity
