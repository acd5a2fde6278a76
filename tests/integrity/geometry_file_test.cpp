#include "integrity/geometry_file.hpp"

#include "integrity/gnss/parse_error.hpp"
#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

namespace skylane::integrity {
namespace {

using nlohmann::json;

TEST(GeometryFile, DefaultsApplyWhenOnlySatellitesAreGiven) {
  const GeometryInput in = parseGeometry(json::parse(R"({"satellites":[{"id":"G01","az_deg":10,"el_deg":45},
      {"id":"E05","az_deg":100,"el_deg":20}]})"), "g.json");
  ASSERT_EQ(in.satellites.size(), 2u);
  EXPECT_EQ(in.satellites[1].sat.constellation, Constellation::kGalileo);
  EXPECT_NEAR(in.satellites[0].look.elevation_rad, maps::deg2rad(45), 1e-15);
  EXPECT_DOUBLE_EQ(in.model.of(Constellation::kGps).ura_m, 0.75);
  EXPECT_DOUBLE_EQ(in.model.of(Constellation::kGalileo).pconst, 1e-4);
  EXPECT_DOUBLE_EQ(in.requirements.phmi_vert, 9.8e-8);
  EXPECT_DOUBLE_EQ(in.requirements.val_m, 35.0);
  EXPECT_EQ(in.model.user_model[0], UserErrorModel::kDualFrequency);
  // ARAIM: the reference rule (MAAST for ARAIM), no consolidation, the mode's own prior for the EMT.
  EXPECT_EQ(in.araim.rule, FaultModeRule::kAddsUntilThreshold);
  EXPECT_EQ(in.araim.fc_thres, 0.0);
  EXPECT_EQ(in.araim.emt_probability, EmtProbability::kModePrior);
}

TEST(GeometryFile, AraimRuleConsolidationAndEmtConventionAreRead) {
  const GeometryInput in = parseGeometry(json::parse(R"({"satellites":[],
      "araim":{"fault_mode_rule":"joint_events","fc_thres":0.01,"emt_probability":"event_product"}})"), "g.json");
  EXPECT_EQ(in.araim.rule, FaultModeRule::kJointEvents);
  EXPECT_DOUBLE_EQ(in.araim.fc_thres, 0.01);
  EXPECT_EQ(in.araim.emt_probability, EmtProbability::kEventProduct);
  EXPECT_EQ(in.araim.exclusion_pl, ExclusionPl::kAllocated);  // the default
  EXPECT_FALSE(in.araim.exclude_constellations);
}

TEST(GeometryFile, ExclusionPlRuleIsReadForRaimAndAraim) {
  const GeometryInput in = parseGeometry(json::parse(R"({"satellites":[],
      "raim":{"exclusion_pl":"remaining_geometry"},
      "araim":{"exclusion_pl":"remaining_geometry","exclude_constellations":true}})"), "g.json");
  EXPECT_EQ(in.raim.exclusion_pl, ExclusionPl::kRemainingGeometry);
  EXPECT_EQ(in.araim.exclusion_pl, ExclusionPl::kRemainingGeometry);
  EXPECT_TRUE(in.araim.exclude_constellations);
}

TEST(GeometryFile, OverridesArePerConstellation) {
  const GeometryInput in = parseGeometry(json::parse(R"({"satellites":[],
      "ism":{"Galileo":{"ura_m":2.0,"psat":1e-4}},
      "user_error_model":{"default":"single_frequency","Galileo":"dual_frequency"},
      "requirements":{"hal_m":10},"raim":{"formula":"brown","pmd":1e-2}})"), "g.json");
  EXPECT_DOUBLE_EQ(in.model.of(Constellation::kGalileo).ura_m, 2.0);
  EXPECT_DOUBLE_EQ(in.model.of(Constellation::kGalileo).psat, 1e-4);
  EXPECT_DOUBLE_EQ(in.model.of(Constellation::kGalileo).ure_m, 0.64);  // untouched
  EXPECT_EQ(in.model.user_model[static_cast<int>(Constellation::kGps)], UserErrorModel::kSingleFrequency);
  EXPECT_EQ(in.model.user_model[static_cast<int>(Constellation::kGalileo)], UserErrorModel::kDualFrequency);
  EXPECT_DOUBLE_EQ(in.requirements.hal_m, 10.0);
  EXPECT_EQ(in.raim.formula, RaimPlFormula::kSlopePbias);
  EXPECT_DOUBLE_EQ(in.raim.pmd, 1e-2);
}

TEST(GeometryFile, ErrorsNameTheFieldTheValueAndWhatWasExpected) {
  struct Case { const char* doc; const char* expected; };
  const Case cases[] = {
      {R"([1,2])", "field '(document)'"},
      {R"({})", "field 'satellites' is missing"},
      {R"({"satellites":[{"id":"X01","az_deg":1,"el_deg":2}]})", "field 'satellites[0].id': got 'X01'"},
      {R"({"satellites":[{"id":"G01","az_deg":1}]})", "field 'satellites[0].el_deg' is missing"},
      {R"({"satellites":[{"id":"G01","az_deg":1,"el_deg":95}]})", "field 'satellites[0].el_deg': got '95'"},
      {R"({"satellites":[{"id":"G01","az_deg":"north","el_deg":5}]})", "field 'satellites[0].az_deg': got '\"north\"'"},
      {R"({"satellites":[{"id":"G01","az_deg":1,"el_deg":5},{"id":"G01","az_deg":1,"el_deg":5}]})", "each satellite listed once"},
      {R"({"satellites":[],"ism":{"Foo":{}}})", "field 'ism.Foo'"},
      {R"({"satellites":[],"ism":{"GPS":{"ura":1}}})", "field 'ism.GPS.ura': got '(unknown field)'"},
      {R"({"satellites":[],"requirements":{"phmi_vert":2}})", "field 'requirements.phmi_vert': got '2', expected a probability"},
      {R"({"satellites":[],"user_error_model":"triple"})", "field 'user_error_model'"},
      {R"({"satellites":[],"sattelites":[]})", "field 'sattelites': got '(unknown field)'"},
      {R"({"satellites":[],"araim":{"fault_mode_rule":"all"}})",
       "field 'araim.fault_mode_rule': got '\"all\"', expected \"adds_until_threshold\", \"joint_events\" or \"blanch2012\""},
      {R"({"satellites":[],"araim":{"fc_thres":1}})", "field 'araim.fc_thres': got '1', expected a fraction in [0, 1)"},
      {R"({"satellites":[],"araim":{"emt_probability":"rate"}})", "field 'araim.emt_probability': got '\"rate\"'"},
      {R"({"satellites":[],"araim":{"exclusion_pl":"plain"}})",
       "field 'araim.exclusion_pl': got '\"plain\"', expected \"allocated\" or \"remaining_geometry\""},
      {R"({"satellites":[],"raim":{"exclusion_pl":1}})", "field 'raim.exclusion_pl': got '1'"},
      {R"({"satellites":[],"araim":{"exclude_constellations":"yes"}})",
       "field 'araim.exclude_constellations': got '\"yes\"', expected true or false"},
  };
  for (const auto& c : cases) {
    const std::string msg = test::messageOf<ParseError>([&] { (void)parseGeometry(json::parse(c.doc), "g.json"); });
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.doc << " → " << msg;
    EXPECT_EQ(msg.rfind("g.json", 0), 0u) << msg;
  }
}

TEST(GeometryFile, JsonSyntaxErrorNamesTheLine) {
  const std::string path = test::scratchPath("bad_geometry.json");
  {
    std::ofstream f(path);
    f << "{\n \"satellites\": [\n  {\"id\": \"G01\",}\n ]\n}\n";
  }
  const std::string msg = test::messageOf<ParseError>([&] { (void)loadGeometryFile(path); });
  EXPECT_NE(msg.find("bad_geometry.json:3"), std::string::npos) << msg;
}

}  // namespace
}  // namespace skylane::integrity
