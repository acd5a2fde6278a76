// Replays every input the fuzzers (fuzz/) found or confirmed: each parser must either succeed
// or throw ParseError, and whatever it accepts must be usable without a crash or exception.
#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "integrity/geometry_file.hpp"
#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/parse_error.hpp"
#include "integrity/gnss/rinex_nav.hpp"
#include "integrity/raim/raim.hpp"
#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

#include <dirent.h>

#include <cmath>

namespace skylane::integrity {
namespace {

std::vector<std::string> regressionFiles() {
  std::vector<std::string> out;
  const std::string dir = test::dataPath("fuzz_regressions");
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d)) {
      if (e->d_name[0] != '.') out.push_back(e->d_name);
    }
    closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void replay(const std::string& name, const std::string& text) {
  const GpsTime t{2320, 0.0};
  if (name.rfind("yuma", 0) == 0 || name.rfind("sem", 0) == 0) {
    const auto recs = name[0] == 'y' ? parseYuma(text, name) : parseSem(text, name);
    for (const auto& r : recs) EXPECT_TRUE(almanacState(r, t).p_ecef.allFinite()) << name;
  } else if (name.rfind("rinex_nav", 0) == 0) {
    const NavigationData nav = parseRinexNav(text, name);
    for (const auto& e : nav.ephemerides) EXPECT_TRUE(satelliteState(e, e.orbit.toe).p_ecef.allFinite()) << name;
  } else if (name.rfind("geometry", 0) == 0) {
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
    if (doc.is_discarded()) return;
    const GeometryInput in = parseGeometry(doc, name);
    const RaimPl pl = raimProtectionLevels(buildGeometry(in.satellites, in.model, in.tau_vert_m), in.raim);
    EXPECT_TRUE(!pl.available || (std::isfinite(pl.hpl_m) && std::isfinite(pl.vpl_m))) << name;
  } else if (name.rfind("text_fields", 0) == 0) {
    const auto d = parseDuration(text);
    EXPECT_TRUE(!d || (std::isfinite(*d) && *d > 0)) << name;
    (void)parseRfc3339(text);
    (void)parseSatId(text);
  } else if (name.rfind("zones", 0) == 0) {
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
    if (doc.is_discarded()) return;
    std::vector<airspace::Zone> zones = airspace::parseZones(doc, name);
    (void)airspace::validateZones(zones, true);
  } else {
    ADD_FAILURE() << "no replay rule for " << name;
  }
}

TEST(FuzzRegression, EveryReproducerGivesAResultOrAParseError) {
  const auto files = regressionFiles();
  ASSERT_GE(files.size(), 14u);
  for (const std::string& f : files) {
    const std::string text = test::readData("fuzz_regressions/" + f);
    try {
      replay(f, text);
    } catch (const ParseError&) {
      // the expected outcome for malformed input
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": unexpected " << typeid(e).name() << ": " << e.what();
    }
  }
}

TEST(FuzzRegression, FindingsNowGiveTheDocumentedErrors) {
  const std::string msg = test::messageOf<ParseError>([] {
    (void)parseYuma(test::readData("fuzz_regressions/yuma-1"), "yuma-1");
  });
  EXPECT_NE(msg.find("field 'week'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("an integer in [0, 10000]"), std::string::npos) << msg;
  EXPECT_FALSE(parseDuration("1e308d").has_value());
  EXPECT_FALSE(parseSatId("G100").has_value());
  EXPECT_FALSE(parseRfc3339("2021-02-29T00:00:00Z").has_value());
  EXPECT_TRUE(parseRfc3339("2020-02-29T00:00:00Z").has_value());
  EXPECT_FALSE(parseRfc3339(" 2020-01-01T00:00:00Z").has_value());
  EXPECT_FALSE(parseRfc3339("2020-01-01T-1:-5:00Z").has_value());
  EXPECT_FALSE(parseRfc3339("2020-01-01T00:00:1e1Z").has_value());
}

}  // namespace
}  // namespace skylane::integrity
