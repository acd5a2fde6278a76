#include "integrity/gnss/rinex_nav.hpp"

#include "integrity/gnss/parse_error.hpp"
#include "tests/test_util.hpp"

namespace skylane::integrity {
namespace {

TEST(RinexNav, Rinex210GpsFileOfStation3040Loads) {
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  EXPECT_DOUBLE_EQ(nav.version, 2.10);
  EXPECT_EQ(nav.ephemerides.size(), 164u);  // (1324 lines − 12 header lines) / 8
  ASSERT_TRUE(nav.klobuchar.has_value());
  EXPECT_DOUBLE_EQ(nav.klobuchar->alpha[0], 1.1180e-08);
  EXPECT_DOUBLE_EQ(nav.klobuchar->beta[2], -1.9660e+05);
  EXPECT_EQ(nav.leap_seconds.value_or(-1), 13);
  const BroadcastEphemeris& e = nav.ephemerides.front();  // PRN 1, 05 4 2 2 0 0.0
  EXPECT_EQ(e.sat.str(), "G01");
  EXPECT_EQ(e.toc.week, 1316);
  EXPECT_DOUBLE_EQ(e.toc.sow, 518400.0 + 7200.0);
  EXPECT_DOUBLE_EQ(e.af0_s, 3.966595977540e-04);
  EXPECT_DOUBLE_EQ(e.orbit.sqrt_a, 5.153636478420e+03);
  EXPECT_DOUBLE_EQ(e.orbit.toe.sow, 5.256000000000e+05);
  EXPECT_EQ(e.orbit.toe.week, 1316);
  EXPECT_DOUBLE_EQ(e.tgd_s, -3.259629011150e-09);
  EXPECT_EQ(e.iode, 140);
}

TEST(RinexNav, EverySharedNavigationFileLoads) {
  for (const char* f : {"gnss/07590920.05n", "gnss/brdc1820.10n", "gnss/Uslo3610.06N"}) {
    const NavigationData nav = loadRinexNav(test::dataPath(f));
    EXPECT_GT(nav.ephemerides.size(), 100u) << f;
    for (const auto& e : nav.ephemerides) {
      EXPECT_LT(std::abs(e.orbit.toe - e.toc), 7200.0 + 1) << f << " line " << e.source_line;
    }
  }
}

TEST(RinexNav, Rinex304MixedFileGivesGpsAndGalileoAndSkipsOthers) {
  const NavigationData nav = loadRinexNav(test::dataPath("rinex3/base_20240624_MN.rnx"));
  EXPECT_DOUBLE_EQ(nav.version, 3.04);
  int gps = 0, gal = 0;
  for (const auto& e : nav.ephemerides) (e.sat.constellation == Constellation::kGps ? gps : gal)++;
  EXPECT_EQ(gps, 13);
  EXPECT_EQ(gal, 10);
  EXPECT_EQ(nav.skipped_records, 2);  // R01 (4 lines) and C01 (8 lines)
  ASSERT_TRUE(nav.klobuchar && nav.nequick_ai);
  EXPECT_DOUBLE_EQ(nav.klobuchar->alpha[0], 1.8626E-08);
  EXPECT_DOUBLE_EQ(nav.klobuchar->beta[3], -2.6214E+05);
  EXPECT_DOUBLE_EQ((*nav.nequick_ai)[0], 1.6175E+02);
  EXPECT_EQ(nav.leap_seconds.value_or(-1), 18);
  // Reference facts from tests/data/rinex3/README.md.
  const auto find = [&](const char* id, int line) -> const BroadcastEphemeris& {
    for (const auto& e : nav.ephemerides) {
      if (e.sat.str() == id && e.source_line == line) return e;
    }
    throw std::runtime_error(std::string("missing ") + id);
  };
  const BroadcastEphemeris& g06 = find("G06", 19);
  EXPECT_DOUBLE_EQ(g06.af0_s, 2.008653245866E-04);
  EXPECT_DOUBLE_EQ(g06.orbit.sqrt_a, 5.153643602371E+03);
  EXPECT_DOUBLE_EQ(g06.orbit.e, 2.935697324574E-03);
  EXPECT_DOUBLE_EQ(g06.orbit.toe.sow, 115200.0);
  EXPECT_EQ(g06.orbit.toe.week, 2320);
  const BroadcastEphemeris& e04 = find("E04", 119);
  EXPECT_DOUBLE_EQ(e04.af0_s, -4.288260824978E-04);
  EXPECT_DOUBLE_EQ(e04.orbit.sqrt_a, 5.440636682510E+03);
  EXPECT_EQ(e04.data_sources, 517);
  EXPECT_EQ(find("E04", 191).data_sources, 258);
  // I/NAV is preferred when I/NAV and F/NAV share a toe.
  const BroadcastEphemeris* sel = selectEphemeris(nav, *parseSatId("E04"), GpsTime{2320, 116400.0});
  ASSERT_NE(sel, nullptr);
  EXPECT_EQ(sel->data_sources, 517);
}

TEST(RinexNav, SelectionPicksClosestHealthyToeWithinTwoHours) {
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  const SatId g01{Constellation::kGps, 1};
  const BroadcastEphemeris* e = selectEphemeris(nav, g01, GpsTime{1316, 525600.0 + 100});
  ASSERT_NE(e, nullptr);
  EXPECT_DOUBLE_EQ(e->orbit.toe.sow, 525600.0);
  EXPECT_EQ(selectEphemeris(nav, g01, GpsTime{1316, 0.0}), nullptr);  // nothing that day
}

TEST(RinexNav, MalformedTruncatedAndEmptyFilesNameLineAndField) {
  const std::string good = test::readData("gnss/30400920.05n");
  std::string bad_sqrta = good;
  bad_sqrta.replace(bad_sqrta.find("5.153636478420D+03"), 18, "5.15363647842OD+03");
  std::string wrong_type = good;
  wrong_type[20] = 'O';
  struct Case { const char* name; std::string text; const char* expected; };
  const Case cases[] = {
      {"empty", "", "nav.rnx:1: field 'RINEX VERSION / TYPE' is missing"},
      {"truncated record", good.substr(0, good.find("5.256000000000D+05")), "nav.rnx:17: field 'i0' is missing, expected broadcast orbit line 4 (record is truncated)"},
      {"bad number", bad_sqrta, "nav.rnx:15: field 'sqrt(A)': got '5.15363647842OD+03'"},
      {"not a nav file", wrong_type, "field 'file type': got 'O'"},
      {"no end of header", good.substr(0, 300), "END OF HEADER"},
  };
  for (const auto& c : cases) {
    const std::string msg = test::messageOf<ParseError>([&] { (void)parseRinexNav(c.text, "nav.rnx"); });
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.name << ": " << msg;
  }
}

}  // namespace
}  // namespace skylane::integrity
