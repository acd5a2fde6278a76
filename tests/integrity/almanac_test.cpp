#include "integrity/gnss/almanac.hpp"

#include "integrity/gnss/orbit_age.hpp"
#include "integrity/gnss/parse_error.hpp"
#include "tests/test_util.hpp"

#include <cmath>
#include <cstdio>

namespace skylane::integrity {
namespace {

struct AlmanacCase {
  const char* file;
  std::size_t records;
  Constellation constellation;
  int first_prn;
};

TEST(Almanac, EverySharedYumaFileLoads) {
  const AlmanacCase cases[] = {
      {"gnss/almmops.txt", 24, Constellation::kGps, 1},
      {"gnss/almgps24plus3.txt", 27, Constellation::kGps, 1},
      {"gnss/alm01jan2020.txt", 31, Constellation::kGps, 1},
      {"gnss/alm_gps_ed259.txt", 24, Constellation::kGps, 1},
      {"gnss/almgalileo24_week703.txt", 24, Constellation::kGalileo, 1},
      {"gnss/almgalileo.txt", 30, Constellation::kGalileo, 1},
      {"gnss/alm_gal_ed259.txt", 24, Constellation::kGalileo, 1},
  };
  for (const auto& c : cases) {
    const auto recs = loadAlmanac(test::dataPath(c.file));
    EXPECT_EQ(recs.size(), c.records) << c.file;
    ASSERT_FALSE(recs.empty());
    EXPECT_EQ(recs.front().sat.constellation, c.constellation) << c.file;
    EXPECT_EQ(recs.front().sat.prn, c.first_prn) << c.file;
  }
}

TEST(Almanac, MopsRecordFieldsAreReadExactly) {
  const auto recs = loadAlmanac(test::dataPath("gnss/almmops.txt"));
  const AlmanacRecord& r = recs.front();  // PRN 01 (first record of the file)
  EXPECT_EQ(r.week_field, 703);
  EXPECT_DOUBLE_EQ(r.orbit.toe.sow, 344063.0);
  EXPECT_DOUBLE_EQ(r.orbit.i0_rad, 0.9599310886);
  EXPECT_DOUBLE_EQ(r.orbit.sqrt_a, 5153.620087);
  EXPECT_DOUBLE_EQ(r.orbit.omega0_rad, 4.762078504);
  EXPECT_DOUBLE_EQ(r.orbit.m0_rad, 4.679681510);
}

TEST(Almanac, CircularOrbitStaysOnItsSphereAndInclination) {
  // For e = 0 the radius is A and |z| ≤ A·sin i: an independent check of the Kepler solution.
  const auto recs = loadAlmanac(test::dataPath("gnss/almmops.txt"));
  const GpsTime t0{2086, 0.0};
  for (const auto& r : recs) {
    for (double dt = 0; dt < 86400; dt += 3600) {
      const SatelliteState s = almanacState(r, t0.plus(dt));
      const double a = r.orbit.sqrt_a * r.orbit.sqrt_a;
      EXPECT_NEAR(s.p_ecef.norm(), a, 1e-6) << r.sat.str();
      EXPECT_LE(std::abs(s.p_ecef.z()), a * std::sin(r.orbit.i0_rad) + 1e-6);
      EXPECT_DOUBLE_EQ(s.relativistic_s, 0.0);
    }
  }
}

TEST(Almanac, AfterOneOrbitalPeriodOnlyTheEarthHasTurned) {
  // The MOPS constellation has e = 0 and Ω̇ = 0: after one period 2π√(a³/μ) the satellite is at
  // the same inertial place, so its ECEF position is the first one turned by −Ω̇e·T about z.
  const auto recs = loadAlmanac(test::dataPath("gnss/almmops.txt"));
  for (const AlmanacRecord& r : recs) {
    const double a = r.orbit.sqrt_a * r.orbit.sqrt_a;
    const double period = 2 * M_PI * std::sqrt(a * a * a / 3.986005e14);
    EXPECT_NEAR(period, 43077.27, 0.01);  // 11 h 57 min 57 s for √A = 5153.62
    const GpsTime t0{2086, 1000.0};
    const Eigen::Vector3d p0 = almanacState(r, t0).p_ecef;
    const Eigen::Vector3d p1 = almanacState(r, t0.plus(period)).p_ecef;
    const double th = 7.2921151467e-5 * period;
    const Eigen::Vector3d expect(std::cos(th) * p0.x() + std::sin(th) * p0.y(), -std::sin(th) * p0.x() + std::cos(th) * p0.y(),
                                 p0.z());
    EXPECT_LT((p1 - expect).norm(), 1e-3) << r.sat.str();
  }
}

TEST(Almanac, WeekIsResolvedNearTheRequestedTime) {
  EXPECT_EQ(resolveAlmanacEpoch(38, 0.0, GpsTime{2086, 0}).week, 2086);   // 10-bit week of Jan 2020
  EXPECT_EQ(resolveAlmanacEpoch(1930, 0.0, GpsTime{2446, 0}).week, 1930);  // full week kept
  EXPECT_EQ(resolveAlmanacEpoch(316, 0.0, GpsTime{1316, 0}).week, 1340);   // 316 + 1024 nearest 1316
}

TEST(Almanac, WeekIsModulo1024EvenWhenItIsBelow256) {
  // GIVEN week 38 as SEM and YUMA write it (modulo 1024: week 2086, 2020-01-04)
  // WHEN resolved near 2025-06-01 (week 2369)
  // THEN it stays week 2086 (5 years old), never 38 + 9·256 = 2342 (26 weeks, as a modulo-256
  // reading would have it)
  const GpsTime june_2025 = *parseRfc3339("2025-06-01T00:00:00Z");
  EXPECT_EQ(june_2025.week, 2369);
  EXPECT_EQ(resolveAlmanacEpoch(38, 503808.0, june_2025).week, 2086);
  // AND week 0 itself is 1024 or 2048, whichever is nearer
  EXPECT_EQ(resolveAlmanacEpoch(0, 0.0, GpsTime{1500, 0}).week, 1024);
  EXPECT_EQ(resolveAlmanacEpoch(0, 0.0, GpsTime{1600, 0}).week, 2048);
}

TEST(Almanac, WeekResolutionAtTheRollOverBoundaries) {
  // Week 1023 near the second roll-over (week 2048 = 2019-04-07) is week 2047, the last week
  // before it, seen from either side of the boundary.
  EXPECT_EQ(resolveAlmanacEpoch(1023, 604000.0, GpsTime{2047, 603000.0}).week, 2047);
  EXPECT_EQ(resolveAlmanacEpoch(1023, 604000.0, GpsTime{2048, 100.0}).week, 2047);
  // Week 0 seen from just before the roll-over is the week after it.
  EXPECT_EQ(resolveAlmanacEpoch(0, 100.0, GpsTime{2047, 604000.0}).week, 2048);
  EXPECT_EQ(resolveAlmanacEpoch(0, 100.0, GpsTime{2048, 200.0}).week, 2048);
  // Before the first roll-over a small week is the week as written (never negative).
  EXPECT_EQ(resolveAlmanacEpoch(703, 344063.0, GpsTime{700, 0}).week, 703);
  EXPECT_EQ(resolveAlmanacEpoch(1023, 0.0, GpsTime{0, 0}).week, 1023);
  // A written week of 1024 or more is a full week, wherever `near` is.
  EXPECT_EQ(resolveAlmanacEpoch(1024, 0.0, GpsTime{2100, 0}).week, 1024);
}

/// Writes one YUMA record as SEM (semicircles), so both parsers can be compared.
std::string semFromYuma(const std::vector<AlmanacRecord>& recs) {
  std::string out = std::to_string(recs.size()) + " CONVERTED.ALM\n";
  char buf[512];
  std::snprintf(buf, sizeof buf, "%d %.0f\n", recs.front().week_field, recs.front().orbit.toe.sow);
  out += buf;
  for (const auto& r : recs) {
    const double sc = M_PI;
    std::snprintf(buf, sizeof buf,
                  "\n%d\n%d\n0\n %.14E %.14E %.14E\n %.14E %.14E %.14E\n %.14E %.14E %.14E\n0\n11\n", r.sat.prn,
                  r.sat.prn + 30, r.orbit.e, r.orbit.i0_rad / sc - 0.30, r.orbit.omega_dot_radps / sc, r.orbit.sqrt_a,
                  r.orbit.omega0_rad / sc, r.orbit.omega_rad / sc, r.orbit.m0_rad / sc, r.af0_s, r.af1_sps);
    out += buf;
  }
  return out;
}

TEST(Almanac, SemAndYumaOfTheSameConstellationGiveTheSamePositions) {
  const auto yuma = loadAlmanac(test::dataPath("gnss/alm01jan2020.txt"));
  const auto sem = parseSem(semFromYuma(yuma), "converted.al3");
  ASSERT_EQ(sem.size(), yuma.size());
  const GpsTime t{2086, 7200.0};
  for (std::size_t i = 0; i < sem.size(); ++i) {
    EXPECT_EQ(sem[i].sat, yuma[i].sat);
    EXPECT_LT((almanacState(sem[i], t).p_ecef - almanacState(yuma[i], t).p_ecef).norm(), 1e-3) << yuma[i].sat.str();
  }
}

TEST(Almanac, SemWeek38OfJanuary2020IsWeek2086AndTooOldFor2025) {
  // GIVEN the almanac of 2020-01-03 as SEM (week 38, t_oa 503808 s)
  const auto sem = parseSem(semFromYuma(loadAlmanac(test::dataPath("gnss/alm01jan2020.txt"))), "alm01jan2020.al3");
  ASSERT_EQ(sem.front().week_field, 38);
  const OrbitFileEpochs epochs = almanacEpochs("alm01jan2020.al3", sem);
  // WHEN its age is taken at a 2020-01-01 start THEN t_oa is in week 2086, 2.8 days later: current
  const OrbitFileAge in_2020 = orbitFileAge(epochs, *parseRfc3339("2020-01-01T00:00:00Z"));
  EXPECT_EQ(in_2020.epoch.week, 2086);
  EXPECT_NEAR(in_2020.age_s, 2 * 86400.0 + 19 * 3600.0 + 56 * 60.0 + 30.0, 1e-6);  // to 2020-01-03T19:56:30Z
  EXPECT_EQ(in_2020.verdict, AgeVerdict::kCurrent);
  // AND at a 2025 departure it is an error naming the file, the epoch, the departure, the age
  // and the limit
  const OrbitFileAge in_2025 = orbitFileAge(epochs, *parseRfc3339("2025-06-01T00:00:00Z"));
  EXPECT_EQ(in_2025.epoch.week, 2086);
  EXPECT_EQ(in_2025.verdict, AgeVerdict::kError);
  const std::string msg = test::messageOf<ParseError>([&] { (void)requireUsableAge(in_2025, "the departure"); });
  for (const char* part : {"alm01jan2020.al3", "GPS week 2086, 503808 s", "2020-01-03T19:56:30Z", "the departure 2025-06-01T00:00:00Z",
                           "within 90.0 days", "1975.2 days"}) {
    EXPECT_NE(msg.find(part), std::string::npos) << part << " in: " << msg;
  }
}

TEST(Almanac, SemRealFileLayoutParses) {
  // Layout of the USCG/NAVCEN SEM file (values of PRN 1, week 1042 almanac).
  const std::string text =
      "1 CURRENT.ALM\n1042 405504\n\n1\n63\n0\n"
      " 5.16395568847656E-03  8.67366790771484E-03 -2.53963877912611E-09\n"
      " 5.15364355468750E+03 -2.40289449691772E-01  2.32856512069702E-01\n"
      " 6.94011092185974E-01  6.48498535156250E-05  0.00000000000000E+00\n0\n11\n";
  const auto recs = parseSem(text, "current.al3");
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_EQ(recs[0].sat.prn, 1);
  EXPECT_EQ(recs[0].week_field, 1042);
  EXPECT_DOUBLE_EQ(recs[0].orbit.toe.sow, 405504.0);
  EXPECT_NEAR(recs[0].orbit.i0_rad, (0.30 + 8.67366790771484E-03) * M_PI, 1e-15);
  EXPECT_NEAR(recs[0].orbit.omega0_rad, -2.40289449691772E-01 * M_PI, 1e-15);
}

struct BadInput {
  const char* name;
  std::string text;
  const char* expected_in_message;
};

TEST(Almanac, MalformedTruncatedAndEmptyInputsNameLineAndField) {
  const std::string good = test::readData("gnss/almmops.txt");
  const std::string first_record = good.substr(0, good.find("\n\n") + 1);
  std::string bad_number = first_record;
  bad_number.replace(bad_number.find("0.9599310886"), 12, "0.95x9310886");
  std::string bad_label = first_record;
  bad_label.replace(bad_label.find("SQRT(A)"), 7, "SQRT(B)");
  std::string bad_ecc = first_record;
  bad_ecc.replace(bad_ecc.find("0.0\nTime of"), 3, "1.5");
  const BadInput cases[] = {
      {"empty", "", "at least one YUMA record"},
      {"truncated", first_record.substr(0, first_record.find("Mean Anom")), "almanac.txt:11: field 'Mean Anom'"},
      {"bad number", bad_number, "almanac.txt:6: field 'Orbital Inclination': got '0.95x9310886'"},
      {"bad label", bad_label, "almanac.txt:8: field 'SQRT(A)'"},
      {"eccentricity", bad_ecc, "field 'eccentricity'"},
      {"garbage", "hello world\n", "almanac.txt:1: field 'record header'"},
  };
  for (const auto& c : cases) {
    const std::string msg = test::messageOf<ParseError>([&] { (void)parseYuma(c.text, "almanac.txt"); });
    EXPECT_NE(msg.find(c.expected_in_message), std::string::npos) << c.name << ": " << msg;
  }
  const std::string sem_msg = test::messageOf<ParseError>([] { (void)parseSem("2 X\n1042 405504\n\n1\n63\n", "a.al3"); });
  EXPECT_NE(sem_msg.find("truncated"), std::string::npos) << sem_msg;
  const std::string load_msg = test::messageOf<ParseError>([] { (void)loadAlmanac("/nonexistent/alm.txt"); });
  EXPECT_NE(load_msg.find("/nonexistent/alm.txt"), std::string::npos) << load_msg;
}

}  // namespace
}  // namespace skylane::integrity
