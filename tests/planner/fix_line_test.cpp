// The direct reading of plain JSON-lines fixes (planner/tracking/fix_line.cpp) against the
// general one (nlohmann's document + parseTrackFixJson): on generated lines — plain ones with
// every field in any order, spacing and number form, and lines that leave the plain form or
// the accepted range one way at a time, each also cut and with a byte changed — the direct way
// gives a fix only when the general one gives the same fix, and gives one for every plain line
// the general way accepts; parseTrackFixLine's errors are the general way's, word for word.

#include "maps/json_node.hpp"
#include "planner/tracking/track_fix.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace skylane::planner {
namespace {

/// The general way: a fix, or its error message.
struct General {
  std::optional<TrackFix> fix;
  std::string error;
};

General general(const std::string& line, const std::string& source) {
  General g;
  try {
    g.fix = parseTrackFixJson(maps::parseJsonLine(line, source), source);
  } catch (const std::exception& e) {
    g.error = e.what();
  }
  return g;
}

/// Every member the JSON line can set, compared exactly (the same doubles, not near ones).
void expectSameFix(const TrackFix& a, const TrackFix& b, const std::string& line) {
  EXPECT_EQ(a.flight, b.flight) << line;
  EXPECT_EQ(a.time.week, b.time.week) << line;
  EXPECT_EQ(a.time.sow, b.time.sow) << line;
  EXPECT_EQ(a.lat_rad, b.lat_rad) << line;
  EXPECT_EQ(a.lon_rad, b.lon_rad) << line;
  EXPECT_EQ(a.h_ell_m, b.h_ell_m) << line;
  EXPECT_EQ(a.hpl_m, b.hpl_m) << line;
  EXPECT_EQ(a.vpl_m, b.vpl_m) << line;
  EXPECT_EQ(a.baro_h_m, b.baro_h_m) << line;
  EXPECT_EQ(a.mag_heading_rad, b.mag_heading_rad) << line;
  EXPECT_EQ(a.pl_source, b.pl_source) << line;
  EXPECT_EQ(a.source, b.source) << line;
  EXPECT_EQ(a.ranges.size(), b.ranges.size()) << line;
  EXPECT_EQ(a.ins.has_value(), b.ins.has_value()) << line;
  EXPECT_EQ(a.imu.has_value(), b.imu.has_value()) << line;
  EXPECT_FALSE(a.velocity_enu_mps || b.velocity_enu_mps || a.attitude_rad || b.attitude_rad) << line;
}

/// A number as a JSON text in one of its forms: integer, decimal, exponent, negative zero.
std::string numberText(double v, std::mt19937& rng) {
  char buf[64];
  switch (std::uniform_int_distribution<int>(0, 4)(rng)) {
    case 0: std::snprintf(buf, sizeof buf, "%.0f", std::round(v)); break;
    case 1: std::snprintf(buf, sizeof buf, "%.9f", v); break;
    case 2: std::snprintf(buf, sizeof buf, "%.17g", v); break;
    case 3: std::snprintf(buf, sizeof buf, "%.6e", v); break;
    default: std::snprintf(buf, sizeof buf, "%.3E", v); break;
  }
  return buf;
}

/// A line with the plain fields, in a random order and spacing; `variant` > 0 changes one thing
/// (a value out of range, a field missing or repeated, one of another type, an escape, …).
std::string plainLine(std::mt19937& rng, int variant) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::pair<std::string, std::string>> members = {
      {"flight", "\"F" + std::to_string(rng() % 1000) + "\""},
      {"time", "\"2026-12-02T14:" + std::to_string(10 + rng() % 50) + ":0" + std::to_string(rng() % 10) + (u(rng) < 0.5 ? ".250Z\"" : "Z\"")},
      {"lat", numberText(-90.0 + 180.0 * u(rng), rng)},
      {"lon", numberText(-180.0 + 360.0 * u(rng), rng)},
      {"h_ell_m", numberText(-100.0 + 3000.0 * u(rng), rng)},
      {"hpl_m", numberText(20.0 * u(rng), rng)},
      {"vpl_m", numberText(30.0 * u(rng), rng)}};
  if (u(rng) < 0.3) members.emplace_back("baro_h_m", numberText(500.0 * u(rng), rng));
  if (u(rng) < 0.3) members.emplace_back("mag_heading_deg", numberText(-360.0 + 720.0 * u(rng), rng));
  if (u(rng) < 0.2) members[0] = {"vehicle", "\"V" + std::to_string(rng() % 100) + "\""};
  switch (variant) {
    case 1: members[2].second = "90.5"; break;
    case 2: members[3].second = "-180.000001"; break;
    case 3: members[4].second = "1e6"; break;
    case 4: members[5].second = "-0.1"; break;
    case 5: members.erase(members.begin() + 6); break;  // vpl_m missing
    case 6: members.push_back(members[2]); break;         // lat twice
    case 7: members.emplace_back("vehicle", "\"V1\""); break;
    case 8: members[0].second = "\"F\\u0031\""; break;       // an escape
    case 9: members[0].second = "17"; break;                 // an integer flight
    case 10: members[2].second = "\"47.1\""; break;          // a string latitude
    case 11: members[1].second = "\"2026-13-02T14:00:00Z\""; break;
    case 12: members[0].second = "\"\""; break;
    case 13: members.emplace_back("imu", "{\"grade\": \"tactical\", \"sigma_n_m\": 1, \"sigma_e_m\": 1, \"sigma_u_m\": 2}"); break;
    case 14: members.emplace_back("speed", "3"); break;
    case 15: members[4].second = "1e400"; break;
    case 16: members[5].second = "01.5"; break;
    case 17: members[2].second = "NaN"; break;
    case 18: members[0].second = "\"Zürich\""; break;
    case 19: members[5].second = "null"; break;
    default: break;
  }
  std::shuffle(members.begin(), members.end(), rng);
  const char* spaces[] = {"", " ", "  ", "\t"};
  auto sp = [&] { return std::string(spaces[rng() % 4]); };
  std::string line = sp() + "{";
  for (std::size_t i = 0; i < members.size(); ++i) {
    line += (i ? "," : "") + sp() + "\"" + members[i].first + "\"" + sp() + ":" + sp() + members[i].second + sp();
  }
  return line + "}" + sp();
}

/// Checks one line both ways; whether the direct way read it.
bool checkBothWays(const std::string& line) {
  const std::string source = "gen.jsonl:1";
  const General g = general(line, source);
  const std::optional<TrackFix> direct = parsePlainFixLine(line, source);
  if (direct) {
    EXPECT_TRUE(g.fix) << "the direct way read a line the general way refuses (" << g.error << "): " << line;
    if (g.fix) expectSameFix(*direct, *g.fix, line);
  }
  try {
    const TrackFix f = parseTrackFixLine(line, source);
    EXPECT_TRUE(g.fix) << line;
    if (g.fix) expectSameFix(f, *g.fix, line);
  } catch (const std::exception& e) {
    EXPECT_EQ(e.what(), g.error) << line;
  }
  return direct.has_value();
}

TEST(FixLine, PlainLinesAreReadDirectlyAndGiveTheGeneralWaysFix) {
  std::mt19937 rng(20261202);
  int direct = 0;
  for (int i = 0; i < 3000; ++i) {
    const std::string line = plainLine(rng, 0);
    ASSERT_TRUE(general(line, "gen.jsonl:1").fix) << line;
    direct += checkBothWays(line);
  }
  EXPECT_EQ(direct, 3000);  // every plain line the general way accepts is read directly
}

TEST(FixLine, EveryOtherLineGoesTheGeneralWayWithItsFixOrItsError) {
  std::mt19937 rng(7);
  for (int i = 0; i < 4000; ++i) {
    const int variant = 1 + i % 19;
    const std::string line = plainLine(rng, variant);
    // Each variant leaves the plain form (an escape, another type, a nested block, a repeated or
    // unknown field, a literal) or the accepted range: never read directly.
    EXPECT_FALSE(checkBothWays(line)) << "variant " << variant << ": " << line;
    // The line cut, and with one byte changed: the same holds.
    (void)checkBothWays(line.substr(0, rng() % (line.size() + 1)));
    std::string changed = line;
    changed[rng() % changed.size()] = static_cast<char>(rng() % 256);
    (void)checkBothWays(changed);
  }
}

TEST(FixLine, ReadingIntoOneFixReplacesAllItHeld) {
  // A stream reads every line into one TrackFix (parseTrackFixLine(text, source, fix)), keeping
  // its strings' storage: nothing of a line may stay for the next — not the pseudoranges, IMU
  // increments or INS block of a general line before a plain one, nor a plain line's barometric
  // height before one without. Lines of every kind in random order, each compared with a fresh
  // reading of it.
  std::vector<std::string> lines;
  for (const char* file : {"raw.jsonl", "imu.jsonl", "gnss_ins.jsonl", "onboard.jsonl"}) {
    std::ifstream in(std::string(SKYLANE_TEST_DATA) + "/../../fuzz/corpus/track/" + file);
    for (std::string l; std::getline(in, l);) {
      if (!l.empty()) lines.push_back(l);
    }
  }
  ASSERT_GE(lines.size(), 8u);
  std::mt19937 rng(11);
  for (int i = 0; i < 40; ++i) lines.push_back(plainLine(rng, 0));
  TrackFix kept;
  std::size_t general_ones = 0;
  for (int i = 0; i < 600; ++i) {
    const std::string& line = lines[rng() % lines.size()];
    const std::string source = "a/long/path/to/the/stream.jsonl:" + std::to_string(i + 1);
    parseTrackFixLine(line, source, kept);
    const TrackFix fresh = parseTrackFixLine(line, source);
    EXPECT_EQ(trackFixJson(kept), trackFixJson(fresh)) << line;
    EXPECT_EQ(kept.source, fresh.source);
    EXPECT_EQ(kept.note, fresh.note);
    EXPECT_EQ(kept.pl_source, fresh.pl_source);
    general_ones += !parsePlainFixLine(line, source).has_value();
  }
  EXPECT_GT(general_ones, 50u);  // both ways were taken, each after the other
}

}  // namespace
}  // namespace skylane::planner
