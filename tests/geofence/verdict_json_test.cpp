// The one JSON form of a check and a verdict (geofence/verdict_json.hpp): the fields per kind,
// the rounding and null rules, and the views the outputs take of it.
#include "geofence/verdict_json.hpp"

#include "maps/parse_error.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace skylane::geofence {
namespace {

using nlohmann::json;

Check boxCheck() {
  Check c;
  c.level = Level::kCorridor;
  c.verdict = Verdict::kIndeterminate;
  c.index = 3;
  c.subject = "segment 3";
  c.margin_h_m = 1.23456;
  c.margin_v_m = std::numeric_limits<double>::infinity();
  c.across_joint = true;
  return c;
}

Check zoneCheck() {
  Check c;
  c.level = Level::kZone;
  c.verdict = Verdict::kOutside;
  c.index = 7;
  c.subject = "LSZH-CTR";
  c.name = "Zurich CTR";
  c.restriction = "REQ_AUTHORISATION";
  c.margin_h_m = -0.0004;
  c.margin_v_m = 12.0;
  c.clearance_m = 0.0;
  c.exact = true;
  return c;
}

TEST(VerdictJson, ABoxLevelCheckNamesItsSegmentAndRoundsToTheMillimetre) {
  const json j = boxCheck();
  EXPECT_EQ(j, json::parse(R"({"level": "level1", "verdict": "indeterminate", "subject": "segment 3",
                               "margin_h_m": 1.235, "margin_v_m": null, "segment": 3, "across_joint": true})"));
}

TEST(VerdictJson, AZoneCheckGivesItsClearanceAndHowItWasDecided) {
  const json j = zoneCheck();
  // A zone check says "met" (not "outside": the volume is in the zone) and names the zone.
  EXPECT_EQ(j, json::parse(R"({"level": "zone", "verdict": "met", "subject": "LSZH-CTR", "margin_h_m": -0.0,
                               "margin_v_m": 12.0, "clearance_m": 0.0, "exact": true, "name": "Zurich CTR",
                               "restriction": "REQ_AUTHORISATION"})"));
  Check clear = zoneCheck();
  clear.verdict = Verdict::kInside;
  EXPECT_EQ(json(clear).at("verdict"), "clear");
  EXPECT_EQ(json(clear).get<Check>().verdict, Verdict::kInside);
  json wrong = json(clear);
  wrong["verdict"] = "inside";  // a box's word on a zone check
  EXPECT_THROW((void)wrong.get<Check>(), maps::ParseError);
  Check unknown = zoneCheck();
  unknown.clearance_m.reset();
  EXPECT_TRUE(json(unknown).at("clearance_m").is_null());
}

TEST(VerdictJson, AVerdictListsItsChecksInTheirOneForm) {
  FenceVerdict v;
  v.verdict = Verdict::kOutside;
  v.violated = Level::kZone;
  v.checks = {boxCheck(), zoneCheck()};
  const json j = v;
  EXPECT_EQ(j.at("verdict"), "outside");
  EXPECT_EQ(j.at("violated"), "zone");
  ASSERT_EQ(j.at("checks").size(), 2u);
  EXPECT_EQ(j.at("checks")[0], json(boxCheck()));
  EXPECT_EQ(j.at("checks")[1], json(zoneCheck()));
  v.violated.reset();
  EXPECT_TRUE(json(v).at("violated").is_null());
}

TEST(VerdictJson, AViewKeepsOnlyTheMembersAskedFor) {
  const json view = pickMembers(json(zoneCheck()), {"subject", "clearance_m", "segment"});
  EXPECT_EQ(view, json::parse(R"({"subject": "LSZH-CTR", "clearance_m": 0.0})"));
}

}  // namespace
}  // namespace skylane::geofence
