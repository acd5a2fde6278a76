#include "integrity/gnss/orbit_age.hpp"

#include "integrity/gnss/orbit_source.hpp"
#include "integrity/gnss/parse_error.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

namespace skylane::integrity {
namespace {

GpsTime at(const char* rfc3339) { return *parseRfc3339(rfc3339); }

/// Whether every part occurs in the text (the failure names the missing one).
::testing::AssertionResult containsAll(const std::string& text, const std::vector<std::string>& parts) {
  for (const std::string& p : parts) {
    if (text.find(p) == std::string::npos) return ::testing::AssertionFailure() << "'" << p << "' not in: " << text;
  }
  return ::testing::AssertionSuccess();
}

TEST(OrbitAge, LimitsAreOrdered) {
  EXPECT_LT(kAlmanacAgeLimits.warning_s, kAlmanacAgeLimits.error_s);
  EXPECT_LT(kEphemerisAgeLimits.warning_s, kEphemerisAgeLimits.error_s);
  EXPECT_DOUBLE_EQ(kAlmanacAgeLimits.warning_s, 7 * 86400.0);
  EXPECT_DOUBLE_EQ(kEphemerisAgeLimits.warning_s, 4 * 3600.0);
}

TEST(OrbitAge, AlmanacOfTheWeekIsCurrentTenDaysOldWarnsFiveYearsOldIsAnError) {
  // GIVEN the YUMA almanac of 2020-01-03T19:56:30Z (week 38 as written, t_oa 503808 s)
  const std::string file = test::dataPath("gnss/alm01jan2020.txt");
  const OrbitFileEpochs epochs = almanacEpochs(file, loadAlmanac(file));
  // WHEN the mission starts 2020-01-01 THEN it is current and nothing is said
  const OrbitFileAge current = orbitFileAge(epochs, at("2020-01-01T00:00:00Z"));
  EXPECT_EQ(current.verdict, AgeVerdict::kCurrent);
  EXPECT_EQ(current.epoch.week, 2086);
  EXPECT_EQ(requireUsableAge(current, "--start"), "");
  // WHEN it starts 2020-01-14 (10.2 days after t_oa) THEN a warning names the file, the epoch,
  // the start, the age and the limit
  const OrbitFileAge ten_days = orbitFileAge(epochs, at("2020-01-14T00:00:00Z"));
  EXPECT_EQ(ten_days.verdict, AgeVerdict::kWarning);
  EXPECT_TRUE(containsAll(requireUsableAge(ten_days, "--start"),
                          {file, "almanac's t_oa 2020-01-03T19:56:30Z (GPS week 2086, 503808 s)", "is 10.2 days from --start 2020-01-14T00:00:00Z",
                           "beyond the 7.0 days warning limit"}));
  // WHEN the departure is in 2025 THEN it is an error (t_oa still resolved to week 2086)
  const OrbitFileAge old = orbitFileAge(epochs, at("2025-03-01T09:00:00Z"));
  EXPECT_EQ(old.verdict, AgeVerdict::kError);
  EXPECT_EQ(old.epoch.week, 2086);
  const std::string msg = test::messageOf<ParseError>([&] { (void)requireUsableAge(old, "the departure"); });
  EXPECT_TRUE(containsAll(msg, {file + ": field 'almanac epoch t_oa': got '2020-01-03T19:56:30Z (GPS week 2086, 503808 s)'",
                                "an almanac within 90.0 days of the departure 2025-03-01T09:00:00Z", "days from it"}));
}

TEST(OrbitAge, AlmanacAgeIsSymmetricInTime) {
  // An almanac ten days after the start is as stale as one ten days before.
  const std::string file = test::dataPath("gnss/alm01jan2020.txt");
  const OrbitFileEpochs epochs = almanacEpochs(file, loadAlmanac(file));
  const GpsTime toa{2086, 503808.0};
  EXPECT_NEAR(orbitFileAge(epochs, toa.plus(-10 * 86400.0)).age_s, 10 * 86400.0, 1e-6);
  EXPECT_NEAR(orbitFileAge(epochs, toa.plus(10 * 86400.0)).age_s, 10 * 86400.0, 1e-6);
  EXPECT_EQ(orbitFileAge(epochs, toa.plus(-10 * 86400.0)).verdict, AgeVerdict::kWarning);
}

TEST(OrbitAge, EphemerisAgeIsTheDistanceToEachSatellitesNearestToe) {
  // GIVEN the IGS broadcast file of 2010-07-01 (every satellite every 2 h, 00:00 … 23:59:44)
  const std::string file = test::dataPath("gnss/brdc1820.10n");
  const OrbitFileEpochs epochs = ephemerisEpochs(file, loadRinexNav(file));
  // WHEN the mission is at noon THEN every satellite has a t_oe within 2 h: current
  const OrbitFileAge noon = orbitFileAge(epochs, at("2010-07-01T12:00:00Z"));
  EXPECT_EQ(noon.verdict, AgeVerdict::kCurrent);
  EXPECT_LE(noon.age_s, 2 * 3600.0 + 60.0);
  // WHEN it is 06:00 the next day THEN the last t_oe is ≥ 6 h back: a warning
  const OrbitFileAge next_morning = orbitFileAge(epochs, at("2010-07-02T06:00:00Z"));
  EXPECT_EQ(next_morning.verdict, AgeVerdict::kWarning);
  EXPECT_GE(next_morning.age_s, 6 * 3600.0 - 60.0);
  EXPECT_LE(next_morning.age_s, 8 * 3600.0 + 60.0);
  EXPECT_TRUE(containsAll(requireUsableAge(next_morning, "the departure"),
                          {file, "ephemeris's nearest t_oe 2010-07-01T", "from the departure 2010-07-02T06:00:00Z",
                           "beyond the 4.0 h warning limit"}));
  // WHEN it is three weeks later THEN it is an error
  const OrbitFileAge later = orbitFileAge(epochs, at("2010-07-22T06:00:00Z"));
  EXPECT_EQ(later.verdict, AgeVerdict::kError);
  EXPECT_TRUE(containsAll(test::messageOf<ParseError>([&] { (void)requireUsableAge(later, "the departure"); }),
                          {file, "field 'ephemeris epoch t_oe'", "an ephemeris within 7.0 days of the departure 2010-07-22T06:00:00Z"}));
}

TEST(OrbitAge, OrbitSourceReportsEachFileByName) {
  // GIVEN an almanac and a navigation file loaded as a mission's "orbits"
  const std::string alm = test::dataPath("gnss/alm01jan2020.txt"), nav = test::dataPath("gnss/brdc1820.10n");
  const OrbitSource orbits = loadOrbitFiles({alm, nav}, "mission.json", "$.orbits");
  // WHEN their ages are taken at the almanac's time THEN each file has its own verdict
  const std::vector<OrbitFileAge> ages = orbits.fileAges(at("2020-01-02T00:00:00Z"));
  ASSERT_EQ(ages.size(), 2u);
  EXPECT_EQ(ages[0].file, alm);
  EXPECT_EQ(ages[0].kind, OrbitKind::kAlmanac);
  EXPECT_EQ(ages[0].verdict, AgeVerdict::kCurrent);
  EXPECT_EQ(ages[1].file, nav);
  EXPECT_EQ(ages[1].kind, OrbitKind::kEphemeris);
  EXPECT_EQ(ages[1].verdict, AgeVerdict::kError);
  // AND records added without a name are named by their kind
  OrbitSource unnamed;
  unnamed.addAlmanac(loadAlmanac(alm));
  EXPECT_EQ(unnamed.fileAges(at("2020-01-02T00:00:00Z")).front().file, "almanac");
}

}  // namespace
}  // namespace skylane::integrity
