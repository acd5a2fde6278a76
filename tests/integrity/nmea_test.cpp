// NMEA 0183 sentences and their assembly into fixes. The GGA and RMC lines are the textbook
// examples (their checksums, *47 and *6A, as printed in the literature); the others are built
// here with the checksum computed independently.
#include "integrity/gnss/nmea.hpp"

#include "integrity/gnss/parse_error.hpp"
#include "tests/test_util.hpp"

#include <cmath>
#include <cstdio>

namespace skylane::integrity {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// "$" + body + "*" + XOR checksum (NMEA 0183 §5.3.1).
std::string sentence(const std::string& body) {
  unsigned sum = 0;
  for (char c : body) sum ^= static_cast<unsigned char>(c);
  char hex[4];
  std::snprintf(hex, sizeof hex, "%02X", sum);
  return "$" + body + "*" + hex;
}

TEST(Nmea, TextbookGgaGivesTheFix) {
  const NmeaSentence s = parseNmeaSentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n", "t");
  const auto& g = std::get<NmeaGga>(s);
  EXPECT_DOUBLE_EQ(g.utc.seconds, 12 * 3600 + 35 * 60 + 19);
  EXPECT_NEAR(*g.lat_rad, (48.0 + 7.038 / 60.0) * kDeg, 1e-12);
  EXPECT_NEAR(*g.lon_rad, (11.0 + 31.0 / 60.0) * kDeg, 1e-12);
  EXPECT_EQ(g.quality, 1);
  EXPECT_EQ(g.satellites, 8);
  EXPECT_DOUBLE_EQ(*g.hdop, 0.9);
  EXPECT_DOUBLE_EQ(*g.alt_msl_m, 545.4);
  EXPECT_DOUBLE_EQ(*g.geoid_separation_m, 46.9);
}

TEST(Nmea, TextbookRmcGivesTheDate) {
  const auto d = std::get<NmeaDate>(
      parseNmeaSentence("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A", "t"));
  EXPECT_EQ(d.year, 1994);
  EXPECT_EQ(d.month, 3);
  EXPECT_EQ(d.day, 23);
}

TEST(Nmea, SouthAndWestAreNegativeAndAnyTalkerIsAccepted) {
  const auto g = std::get<NmeaGga>(parseNmeaSentence(sentence("GNGGA,000001.50,3342.1200,S,07017.4800,W,4,21,0.6,12.0,M,-20.5,M,1.0,0001"), "t"));
  EXPECT_NEAR(*g.lat_rad, -(33.0 + 42.12 / 60.0) * kDeg, 1e-12);
  EXPECT_NEAR(*g.lon_rad, -(70.0 + 17.48 / 60.0) * kDeg, 1e-12);
  EXPECT_DOUBLE_EQ(g.utc.seconds, 1.5);
  EXPECT_EQ(g.quality, 4);
}

TEST(Nmea, GstAndGbsFieldsAreRead) {
  const auto t = std::get<NmeaGst>(parseNmeaSentence(sentence("GPGST,172814.0,0.006,0.023,0.020,273.6,0.023,0.020,0.031"), "t"));
  EXPECT_DOUBLE_EQ(*t.sigma_lat_m, 0.023);
  EXPECT_DOUBLE_EQ(*t.sigma_alt_m, 0.031);
  EXPECT_DOUBLE_EQ(*t.orientation_deg, 273.6);
  const auto b = std::get<NmeaGbs>(parseNmeaSentence(sentence("GPGBS,172814.0,1.2,0.9,2.5,19,0.001,12.3,1.4"), "t"));
  EXPECT_DOUBLE_EQ(*b.err_alt_m, 2.5);
  EXPECT_EQ(*b.failed_satellite, 19);
  EXPECT_DOUBLE_EQ(*b.bias_m, 12.3);
  EXPECT_TRUE(std::holds_alternative<NmeaOther>(parseNmeaSentence(sentence("GPGSV,1,1,00"), "t")));
}

TEST(Nmea, BadInputNamesTheFieldAndWhatWasExpected) {
  const struct {
    std::string line, expected;
  } cases[] = {
      {"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48", "checksum': got '48', expected the XOR of the sentence, 47"},
      {"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", "'*' and two hex digits"},
      {sentence("GPGGA,123519,4867.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), "GGA field 2 (latitude)': got '4867.038', expected minutes below 60"},
      {sentence("GPGGA,123519,4807.038,X,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), "GGA field 3 (hemisphere)': got 'X', expected 'N' or 'S'"},
      {sentence("GPGGA,253519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), "GGA field 1 (UTC hhmmss.ss)"},
      {sentence("GPGGA,123519,4807.038,N,1131.000,E,1,08,0.9,545.4,M,46.9,M,,"), "a longitude dddmm.mmmm"},
      {sentence("GPGBS,172814.0,1.2,0.9,2.5,19,1.5,12.3,1.4"), "a probability 0…1"},
      {sentence("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,310294,003.1,W"), "a valid date"},
      {"GPGGA,123519*47", "starting with '$'"},
  };
  for (const auto& c : cases) {
    const std::string msg = test::messageOf<ParseError>([&] { (void)parseNmeaSentence(c.line, "fixes.nmea:7"); });
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.line << "\n" << msg;
    EXPECT_EQ(msg.rfind("fixes.nmea:7", 0), 0u) << msg;
  }
}

TEST(Nmea, AssemblerJoinsOneEpochAndDatesItFromRmc) {
  NmeaEpochAssembler a;
  EXPECT_FALSE(a.add(parseNmeaSentence("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A", "t")));
  EXPECT_FALSE(a.add(parseNmeaSentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47", "t")));
  EXPECT_FALSE(a.add(parseNmeaSentence(sentence("GPGST,123519,1.0,2.0,1.5,10.0,1.8,1.6,3.0"), "t")));
  EXPECT_FALSE(a.add(parseNmeaSentence(sentence("GPGBS,123519,1.2,0.9,2.5,,,,"), "t")));
  // The next second's GGA closes the epoch.
  const auto fix = a.add(parseNmeaSentence(sentence("GPGGA,123520,4807.040,N,01131.000,E,1,08,0.9,545.5,M,46.9,M,,"), "t"));
  ASSERT_TRUE(fix);
  EXPECT_EQ(formatRfc3339(fix->time), "1994-03-23T12:35:19Z");  // GPS − UTC = 9 s then, shown as UTC
  EXPECT_NEAR(fix->h_ell_m, 545.4 + 46.9, 1e-9);
  ASSERT_TRUE(fix->gst);
  EXPECT_DOUBLE_EQ(*fix->gst->sigma_alt_m, 3.0);
  ASSERT_TRUE(fix->gbs);
  EXPECT_DOUBLE_EQ(*fix->gbs->err_lat_m, 1.2);
  const auto last = a.flush();
  ASSERT_TRUE(last);
  EXPECT_NEAR(last->time - fix->time, 1.0, 1e-9);
  EXPECT_FALSE(last->gst);
}

TEST(Nmea, AssemblerRollsOverMidnightAndSkipsFixlessEpochs) {
  NmeaEpochAssembler a;
  (void)a.add(parseNmeaSentence(sentence("GPZDA,235959.00,31,12,2025,00,00"), "t"));
  (void)a.add(parseNmeaSentence(sentence("GPGGA,235959.00,,,,,0,00,,,,,,,"), "t"));  // no fix yet
  const auto none = a.add(parseNmeaSentence(sentence("GPGGA,000001.00,4722.6100,N,00832.5000,E,1,10,0.8,450.0,M,48.0,M,,"), "t"));
  EXPECT_FALSE(none);  // the fixless epoch gives nothing
  const auto fix = a.flush();
  ASSERT_TRUE(fix);
  EXPECT_EQ(formatRfc3339(fix->time), "2026-01-01T00:00:01Z");
  NmeaEpochAssembler undated;
  (void)undated.add(parseNmeaSentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47", "t"));
  EXPECT_THROW((void)undated.flush(), std::invalid_argument);
}

}  // namespace
}  // namespace skylane::integrity
