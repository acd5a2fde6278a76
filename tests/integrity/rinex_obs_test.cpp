#include "integrity/gnss/rinex_obs.hpp"

#include "integrity/gnss/parse_error.hpp"
#include "tests/test_util.hpp"

#include <cmath>
#include <limits>

namespace skylane::integrity {
namespace {

TEST(RinexObs, Rinex210FileOfStation3040Loads) {
  const ObservationData obs = loadRinexObs(test::dataPath("gnss/30400920.05o"));
  EXPECT_DOUBLE_EQ(obs.version, 2.10);
  EXPECT_EQ(obs.marker_name, "3040");
  ASSERT_TRUE(obs.approx_position_ecef.has_value());
  EXPECT_DOUBLE_EQ(obs.approx_position_ecef->x(), -3978242.4348);
  EXPECT_DOUBLE_EQ(obs.interval_s, 30.0);
  const auto& types = obs.types[static_cast<int>(Constellation::kGps)];
  ASSERT_EQ(types.size(), 4u);  // L1 C1 L2 P2
  EXPECT_EQ(findObsType(types, 'C', 1, "C"), 1);
  EXPECT_EQ(findObsType(types, 'C', 2, "W"), 3);
  EXPECT_EQ(obs.epochs.size(), 120u);  // one hour at 30 s
  const ObservationEpoch& e0 = obs.epochs.front();
  EXPECT_EQ(e0.t.week, 1316);
  EXPECT_DOUBLE_EQ(e0.t.sow, 518400.0);
  ASSERT_EQ(e0.sats.size(), 9u);
  EXPECT_EQ(e0.sats[0].sat.str(), "G03");
  EXPECT_DOUBLE_EQ(e0.sats[0].values[1], 24801780.917);
  EXPECT_DOUBLE_EQ(e0.sats[0].values[3], 24801779.314);
  EXPECT_DOUBLE_EQ(e0.sats[8].values[0], -31201141.133);
}

TEST(RinexObs, EverySharedObservationFileLoads) {
  const ObservationData o = loadRinexObs(test::dataPath("gnss/07590920.05o"));
  EXPECT_EQ(o.epochs.size(), 120u);
}

TEST(RinexObs, Rinex304MixedFileKeepsPerSystemTypes) {
  const ObservationData obs = loadRinexObs(test::dataPath("rinex3/base_20240624_MO.rnx"));
  EXPECT_DOUBLE_EQ(obs.version, 3.04);
  EXPECT_EQ(obs.marker_name, "SEPT");
  ASSERT_TRUE(obs.approx_position_ecef.has_value());
  EXPECT_DOUBLE_EQ(obs.approx_position_ecef->y(), 3562839.5216);
  EXPECT_EQ(obs.types[static_cast<int>(Constellation::kGps)].size(), 17u);
  EXPECT_EQ(obs.types[static_cast<int>(Constellation::kGalileo)].size(), 13u);
  ASSERT_EQ(obs.epochs.size(), 10u);
  // 57 satellites per epoch: 12 G, 9 E, 9 R, 25 C kept; 2 QZSS skipped.
  EXPECT_EQ(obs.epochs[0].sats.size(), 55u);
  EXPECT_EQ(obs.skipped_satellites, 20);
  const auto value = [&](const ObservationEpoch& ep, const char* id, const char* code) {
    const auto sat = *parseSatId(id);
    const auto& types = obs.types[static_cast<int>(sat.constellation)];
    int k = -1;
    for (std::size_t i = 0; i < types.size(); ++i) {
      if (types[i].as_written == code) k = static_cast<int>(i);
    }
    for (const auto& so : ep.sats) {
      if (so.sat == sat) return so.values[static_cast<std::size_t>(k)];
    }
    return std::numeric_limits<double>::quiet_NaN();
  };
  EXPECT_DOUBLE_EQ(value(obs.epochs[0], "G05", "C1C"), 20437584.735);
  EXPECT_DOUBLE_EQ(value(obs.epochs[0], "G05", "C2W"), 20437579.112);
  EXPECT_DOUBLE_EQ(value(obs.epochs[0], "E04", "C1C"), 24494249.114);
  EXPECT_DOUBLE_EQ(value(obs.epochs[0], "E04", "C5Q"), 24494247.975);
  EXPECT_DOUBLE_EQ(value(obs.epochs[9], "G05", "C1C"), 20437518.791);
}

TEST(RinexObs, Rinex2CodesMapToRinex3Meaning) {
  EXPECT_EQ(obsCodeFromRinex2("P2")->attribute, 'W');
  EXPECT_EQ(obsCodeFromRinex2("C1")->attribute, 'C');
  EXPECT_EQ(obsCodeFromRinex2("L2")->kind, 'L');
  EXPECT_FALSE(obsCodeFromRinex2("Q1").has_value());
  EXPECT_EQ(obsCodeFromRinex3("C5Q")->band, 5);
  EXPECT_FALSE(obsCodeFromRinex3("C5").has_value());
}

TEST(RinexObs, MalformedTruncatedAndEmptyFilesNameLineAndField) {
  const std::string good = test::readData("gnss/30400920.05o");
  std::string bad_value = good;
  bad_value.replace(bad_value.find("24801780.917"), 12, "248O1780.917");
  std::string bad_month = good;
  bad_month.replace(bad_month.find(" 05  4  2  0  0  0.0000000"), 7, " 05 14 ");
  struct Case { const char* name; std::string text; const char* expected; };
  const Case cases[] = {
      {"empty", "", "obs.rnx:1: field 'RINEX VERSION / TYPE' is missing"},
      {"truncated", good.substr(0, good.find("-28434148.766")), "(file is truncated)"},
      {"bad value", bad_value, "obs.rnx:19: field 'C1': got '248O1780.917'"},
      {"bad month", bad_month, "obs.rnx:18: field 'epoch'"},
      {"no header end", good.substr(0, 500), "END OF HEADER"},
  };
  for (const auto& c : cases) {
    const std::string msg = test::messageOf<ParseError>([&] { (void)parseRinexObs(c.text, "obs.rnx"); });
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.name << ": " << msg;
  }
}

}  // namespace
}  // namespace skylane::integrity
