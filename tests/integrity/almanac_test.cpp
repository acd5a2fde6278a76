#include "integrity/gnss/almanac.hpp"

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
  EXPECT_EQ(resolveAlmanacEpoch(38, 0.0, GpsTime{2086, 0}).week, 2086);   // 8-bit week of Jan 2020
  EXPECT_EQ(resolveAlmanacEpoch(1930, 0.0, GpsTime{2446, 0}).week, 1930);  // full week kept
  EXPECT_EQ(resolveAlmanacEpoch(316, 0.0, GpsTime{1316, 0}).week, 1340);   // 316 + 1024 nearest 1316
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
