// The level-1 truth of an approval (issue: "APPROVED while the corridor fails everywhere"): PLs
// predicted for the navigation the vehicle has (GNSS alone, GNSS/INS, a receiver's declared
// PLs), each level's availability and worst stretch, the policy's minimum, and the summary line.
#include "planner/approval.hpp"
#include "planner/ins_pl_prediction.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/tracker.hpp"

#include "maps/parse_error.hpp"
#include "tests/planner/simulated_flight.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <optional>
#include <memory>

namespace skylane::planner {
namespace {

using nlohmann::json;

constexpr double kLat0 = 47.3712, kLon0 = 8.5320;

/// A mission 1.5 km east over flat ground at 408 m, no zones, no buildings, departing
/// 2020-01-01T14:00Z (the approval tests' small mission), with `extra` merged in.
json smallMission(const std::string& name, const json& extra = json::object()) {
  const std::string zone_file = test::scratchPath(name + "_zones.json");
  std::ofstream(zone_file) << json{{"formatVersion", "1.0.0"}, {"UASZoneList", json::array()}}.dump();
  json m{{"name", name},
         {"vehicle", {{"lateral_m", 1.5}, {"longitudinal_m", 1.5}, {"cruise_speed_mps", 12}}},
         {"k1", 1.2},
         {"k2", 150},
         {"start", {{"lat", kLat0}, {"lon", kLon0}}},
         {"goal", {{"lat", kLat0}, {"lon", kLon0 + 0.0198}}},
         {"departure", "2020-01-01T14:00:00Z"},
         {"zones", {zone_file}},
         {"ground_amsl_m", 408},
         {"orbits", {test::dataPath("gnss/alm01jan2020.txt")}},
         {"integrity", {{"cost_weight", 0.0}}},
         {"planner", {{"time_limit_s", 10.0}, {"iterations", 600}, {"seed", 3}}}};
  m.merge_patch(extra);
  return m;
}

Mission parsed(const json& doc) { return parseMission(doc, doc.value("name", "m") + ".json", "."); }

// --- the mission's navigation and policy --------------------------------------------------

TEST(MissionNavigation, EachKindIsReadWithItsFields) {
  EXPECT_EQ(parsed(smallMission("nav_default")).navigation.kind, NavigationKind::kGnss);
  EXPECT_EQ(parsed(smallMission("nav_gnss", {{"navigation", {{"kind", "gnss"}}}})).navigation.kind, NavigationKind::kGnss);
  const Mission ins = parsed(smallMission("nav_ins", {{"navigation", {{"kind", "gnss_ins"}, {"imu", "aviation"}}}}));
  EXPECT_EQ(ins.navigation.kind, NavigationKind::kGnssIns);
  EXPECT_EQ(ins.navigation.imu, integrity::ins::ImuGrade::kAviation);
  const Mission rx = parsed(smallMission("nav_rx", {{"navigation", {{"kind", "receiver"}, {"hpl_m", 0.5}, {"vpl_m", 0.8}}},
                                                    {"policy", {{"min_level1_availability", 0.95}}}}));
  EXPECT_EQ(rx.navigation.kind, NavigationKind::kReceiver);
  EXPECT_EQ(rx.navigation.hpl_m, 0.5);
  EXPECT_EQ(rx.navigation.vpl_m, 0.8);
  ASSERT_TRUE(rx.policy.min_level1_availability);
  EXPECT_EQ(*rx.policy.min_level1_availability, 0.95);
}

TEST(MissionNavigation, ErrorsNameTheFieldAndWhatWasExpected) {
  struct Case {
    json extra;
    std::string field, expected;
  };
  const std::vector<Case> cases{
      {{{"navigation", "gnss"}}, "$.navigation", "an object with kind"},
      {{{"navigation", {{"imu", "tactical"}}}}, "$.navigation.kind", ""},
      {{{"navigation", {{"kind", "rtk"}}}}, "$.navigation.kind", "\"gnss\", \"gnss_ins\" or \"receiver\""},
      {{{"navigation", {{"kind", "gnss_ins"}}}}, "$.navigation.imu", ""},
      {{{"navigation", {{"kind", "gnss_ins"}, {"imu", "mems"}}}}, "$.navigation.imu", "\"aviation\", \"tactical\" or \"consumer\""},
      {{{"navigation", {{"kind", "gnss"}, {"imu", "tactical"}}}}, "$.navigation.imu", ""},
      {{{"navigation", {{"kind", "receiver"}, {"hpl_m", 0.5}}}}, "$.navigation.vpl_m", ""},
      {{{"navigation", {{"kind", "receiver"}, {"hpl_m", -1}, {"vpl_m", 1}}}}, "$.navigation.hpl_m", "> 0"},
      {{{"navigation", {{"kind", "receiver"}, {"hpl_m", 1}, {"vpl_m", 1}, {"fallback", "gnss"}}}}, "$.navigation.fallback", ""},
      {{{"policy", {{"min_level1_availability", 95}}}}, "$.policy.min_level1_availability", "[0, 1]"},
      {{{"policy", {{"max_level1_gap_s", 10}}}}, "$.policy.max_level1_gap_s", ""},
  };
  for (const Case& c : cases) {
    const json doc = smallMission("nav_errors", c.extra);
    const std::string msg = test::messageOf<maps::ParseError>([&] { (void)parsed(doc); });
    EXPECT_EQ(msg.rfind("nav_errors.json", 0), 0u) << msg;
    EXPECT_NE(msg.find(c.field), std::string::npos) << c.extra.dump() << " → " << msg;
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.extra.dump() << " → " << msg;
  }
}

// --- availability over samples ------------------------------------------------------------

PredictedSample sampleAt(double t_s, double hpl_m, double vpl_m, bool available = true) {
  PredictedSample s;
  s.t_s = t_s;
  s.lat_rad = 0.8 + 1e-6 * t_s;
  s.lon_rad = 0.15 + 2e-6 * t_s;
  s.pl_available = available;
  s.hpl_m = hpl_m;
  s.vpl_m = vpl_m;
  return s;
}

TEST(LevelAvailability, CountsSamplesWithinBothLimitsAndFindsTheLongestFailingRun) {
  const geofence::AlertLimits limits{2.0, 3.0};
  // GIVEN held, failing (HPL), held, failing ×3 (VPL, no PL, HPL), held on the limit, failing
  const std::vector<PredictedSample> samples{sampleAt(0, 1.0, 1.0), sampleAt(1, 2.5, 1.0), sampleAt(2, 2.0, 3.0),
                                             sampleAt(3, 1.0, 3.5), sampleAt(4, 0.0, 0.0, false), sampleAt(5, 9.0, 1.0),
                                             sampleAt(6, 2.0, 3.0),  sampleAt(7, 2.1, 3.1)};
  const LevelAvailability a = levelAvailability(samples, limits);
  // THEN touching a limit holds it; the longest run is t = 3…5
  EXPECT_EQ(a.samples, 8);
  EXPECT_EQ(a.held, 3);
  EXPECT_DOUBLE_EQ(a.fraction, 3.0 / 8.0);
  ASSERT_TRUE(a.worst_stretch);
  EXPECT_EQ(a.worst_stretch->samples, 3);
  EXPECT_EQ(a.worst_stretch->t_start_s, 3.0);
  EXPECT_EQ(a.worst_stretch->t_end_s, 5.0);
  EXPECT_EQ(a.worst_stretch->duration_s(), 2.0);
  EXPECT_EQ(a.worst_stretch->lat_start_rad, samples[3].lat_rad);
  EXPECT_EQ(a.worst_stretch->lon_end_rad, samples[5].lon_rad);
  // AND every sample held: no stretch; none: the whole route
  EXPECT_FALSE(levelAvailability({sampleAt(0, 1, 1), sampleAt(1, 1, 1)}, limits).worst_stretch);
  const LevelAvailability none = levelAvailability({sampleAt(0, 5, 1), sampleAt(1, 5, 1)}, limits);
  EXPECT_EQ(none.fraction, 0.0);
  EXPECT_EQ(none.worst_stretch->samples, 2);
}

TEST(LevelAvailability, PercentagesSayZeroAndHundredOnlyWhenExact) {
  EXPECT_EQ(availabilityPercent(0.0), "0 %");
  EXPECT_EQ(availabilityPercent(1.0), "100 %");
  EXPECT_EQ(availabilityPercent(0.95), "95 %");
  EXPECT_EQ(availabilityPercent(0.997), "99.7 %");
  EXPECT_EQ(availabilityPercent(0.9999), "99.9 %");
  EXPECT_EQ(availabilityPercent(0.001), "0.1 %");
}

// --- a receiver's declared PLs --------------------------------------------------------------

/// The share of samples with HPL ≤ HAL and VPL ≤ VAL, counted here from the samples.
double heldShare(const ApprovalReport& r, const geofence::AlertLimits& l) {
  int held = 0;
  for (const PredictedSample& s : r.predicted) held += s.pl_available && s.hpl_m <= l.hal_m && s.vpl_m <= l.val_m;
  return static_cast<double>(held) / static_cast<double>(r.predicted.size());
}

TEST(ApprovalNavigation, ADeclaredReceiverPlWithinHal1HoldsLevel1EverywhereAndOneAboveItNowhere) {
  for (const double hpl : {0.5, 2.5}) {
    // GIVEN a receiver declaring HPL (HAL₁ = 1.8 m) and VPL 0.8 m
    Approver a(parsed(smallMission("receiver", {{"navigation", {{"kind", "receiver"}, {"hpl_m", hpl}, {"vpl_m", 0.8}}}})));
    const ApprovalReport r = a.approve();
    ASSERT_TRUE(r.approved) << (r.reasons.empty() ? "" : r.reasons.front().message);
    ASSERT_NEAR(r.limits.level1.hal_m, 1.8, 1e-12);
    ASSERT_GT(r.predicted.size(), 100u);
    // THEN every sample carries the declared PLs
    for (const PredictedSample& s : r.predicted) {
      ASSERT_TRUE(s.pl_available);
      ASSERT_EQ(s.hpl_m, hpl);
      ASSERT_EQ(s.vpl_m, 0.8);
    }
    // AND level 1 is available at every sample, or at none, as counted from the samples
    const double expected = hpl <= r.limits.level1.hal_m ? 1.0 : 0.0;
    EXPECT_EQ(heldShare(r, r.limits.level1), expected);
    EXPECT_EQ(r.level1_availability.fraction, expected) << hpl;
    EXPECT_EQ(r.level1_availability.samples, static_cast<int>(r.predicted.size()));
    EXPECT_EQ(r.level2_availability.fraction, 1.0);
    EXPECT_EQ(r.level1_exceedances, expected == 1.0 ? 0 : static_cast<int>(r.predicted.size()));
    EXPECT_EQ(r.level1_availability.worst_stretch.has_value(), expected == 0.0);
    if (expected == 0.0) {
      EXPECT_EQ(r.level1_availability.worst_stretch->t_start_s, 0.0);
      EXPECT_EQ(r.level1_availability.worst_stretch->t_end_s, r.predicted.back().t_s);
    }
  }
}

TEST(ApprovalNavigation, TheSummaryLineSaysHowMuchOfTheRouteHoldsTheCorridor) {
  Approver fine(parsed(smallMission("summary_fine", {{"navigation", {{"kind", "receiver"}, {"hpl_m", 0.5}, {"vpl_m", 0.8}}}})));
  EXPECT_EQ(approvalSummary(fine.approve()), "APPROVED — corridor ±1.8 m / ±1.8 m held at 100 % of samples");
  Approver gnss(parsed(smallMission("summary_gnss")));
  const ApprovalReport r = gnss.approve();
  ASSERT_TRUE(r.approved);
  ASSERT_EQ(r.level1_availability.held, 0);  // GNSS-only HPLs are metres to tens of metres
  EXPECT_EQ(approvalSummary(r),
            "APPROVED — corridor ±1.8 m / ±1.8 m held at 0 % of samples: expect a monitoring rerun at every fix");
  // AND the report's JSON carries both levels, the navigation and the summary
  const json j = r;
  EXPECT_EQ(j.at("navigation").at("kind"), "gnss");
  EXPECT_EQ(j.at("availability").at("level1").at("fraction"), 0.0);
  EXPECT_EQ(j.at("availability").at("level1").at("worst_stretch").at("samples"), static_cast<int>(r.predicted.size()));
  EXPECT_EQ(j.at("availability").at("level2").at("fraction"), 1.0);
  EXPECT_TRUE(j.at("availability").at("level2").at("worst_stretch").is_null());
  EXPECT_EQ(j.at("level1_exceedances"), static_cast<int>(r.predicted.size()));
  EXPECT_EQ(j.at("summary"), approvalSummary(r));
}

// --- the policy -----------------------------------------------------------------------------

TEST(ApprovalPolicy, ALevel1AvailabilityBelowTheMinimumRejectsNamingTheWorstStretch) {
  // GIVEN a receiver whose declared HPL exceeds HAL₁ and a policy requiring 95 %
  Approver a(parsed(smallMission("policy", {{"navigation", {{"kind", "receiver"}, {"hpl_m", 2.5}, {"vpl_m", 0.8}}},
                                            {"policy", {{"min_level1_availability", 0.95}}},
                                            {"planner", {{"max_replans", 0}}}})));
  const ApprovalReport r = a.approve();
  // THEN it is rejected for availability, naming where and when the corridor is lost
  ASSERT_FALSE(r.approved);
  ASSERT_EQ(r.reasons.size(), 1u);
  const Reason& why = r.reasons.front();
  EXPECT_EQ(why.kind, "availability");
  EXPECT_EQ(why.subject, "level 1");
  ASSERT_TRUE(why.t_s && why.lat_rad && why.lon_rad);
  EXPECT_EQ(*why.t_s, 0.0);
  EXPECT_NEAR(maps::rad2deg(*why.lat_rad), kLat0, 1e-6);
  const std::string end_s = std::to_string(static_cast<int>(std::lround(r.predicted.back().t_s)));
  EXPECT_NE(why.message.find("holds at 0 % of samples, below the policy's 95 %"), std::string::npos) << why.message;
  EXPECT_NE(why.message.find("from t+0 s to t+" + end_s + " s"), std::string::npos) << why.message;
  EXPECT_NE(why.message.find("from 47.37120°, 8.53200°"), std::string::npos) << why.message;
  // AND no later departure passes (the declared PL never changes)
  EXPECT_FALSE(r.earliest_passing_departure);
  EXPECT_EQ(approvalSummary(r).rfind("REJECTED — the corridor (level 1", 0), 0u) << approvalSummary(r);
  // AND a policy it meets approves the same route
  Approver ok(parsed(smallMission("policy_ok", {{"navigation", {{"kind", "receiver"}, {"hpl_m", 1.5}, {"vpl_m", 0.8}}},
                                                {"policy", {{"min_level1_availability", 1.0}}}})));
  EXPECT_TRUE(ok.approve().approved);
}

// --- GNSS/INS -------------------------------------------------------------------------------

/// The median over the samples from `from_s` on of `pl` (NaN when none has one).
double medianOf(const ApprovalReport& r, double from_s, const std::function<std::optional<double>(const PredictedSample&)>& pl) {
  std::vector<double> v;
  for (const PredictedSample& s : r.predicted) {
    if (s.t_s < from_s) continue;
    if (const std::optional<double> x = pl(s)) v.push_back(*x);
  }
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

std::optional<double> faultModeHpl(const PredictedSample& s) { return s.pl_available ? std::optional(s.hpl_m) : std::nullopt; }
std::optional<double> threeHypothesisHpl(const PredictedSample& s) { return s.three_hypothesis_hpl_m; }

TEST(ApprovalNavigation, GnssInsPlsAgainstGnssAloneOnTheSameRouteAndTime) {
  // GIVEN the same route and departure, GNSS alone and GNSS/INS with each IMU grade
  Approver gnss(parsed(smallMission("ins_vs_gnss")));
  const ApprovalReport rg = gnss.approve();
  ASSERT_TRUE(rg.approved);
  std::vector<double> fault_mode_median;
  for (const char* grade : {"aviation", "tactical", "consumer"}) {
    Approver ins(parsed(smallMission("ins_vs_gnss", {{"navigation", {{"kind", "gnss_ins"}, {"imu", grade}}}})));
    const ApprovalReport ri = ins.approve();
    ASSERT_TRUE(ri.approved) << grade;
    ASSERT_EQ(rg.predicted.size(), ri.predicted.size());
    // THEN every sample has both GNSS/INS PLs, and once the filter has converged (after 30 s) its
    // three-hypothesis INS PL is below the GNSS-only PL at every sample (tactical and better)
    int compared = 0;
    for (std::size_t k = 0; k < ri.predicted.size(); ++k) {
      const PredictedSample &g = rg.predicted[k], &i = ri.predicted[k];
      ASSERT_TRUE(i.pl_available) << grade << " " << i.t_s;
      ASSERT_TRUE(i.three_hypothesis_hpl_m && i.three_hypothesis_vpl_m) << grade << " " << i.t_s;
      if (i.t_s < 30.0 || std::string(grade) == "consumer") continue;
      EXPECT_LT(*i.three_hypothesis_hpl_m, g.hpl_m) << grade << " " << i.t_s;
      EXPECT_LT(*i.three_hypothesis_vpl_m, g.vpl_m) << grade << " " << i.t_s;
      ++compared;
    }
    if (std::string(grade) != "consumer") {
      EXPECT_GT(compared, 50) << grade;
    }
    fault_mode_median.push_back(medianOf(ri, 30.0, faultModeHpl));
    // (The fault-mode PL, the one the tracker flies with and the approval checks, bounds a
    // current-epoch satellite fault by the LSR test's detectable bias: it is not below the
    // snapshot RAIM PL here — printed, so that the report's numbers can be traced.)
    std::printf("%s: median HPL after 30 s: GNSS %.2f m; GNSS/INS fault-mode %.2f m, three-hypothesis %.2f m\n", grade,
                medianOf(rg, 30.0, faultModeHpl), fault_mode_median.back(), medianOf(ri, 30.0, threeHypothesisHpl));
  }
  // AND a better IMU never predicts a larger fault-mode PL
  EXPECT_LE(fault_mode_median[0], fault_mode_median[1] + 1e-9);
  EXPECT_LE(fault_mode_median[1], fault_mode_median[2] + 1e-9);
}

TEST(ApprovalNavigation, GnssInsPredictionIsTheTrackersLivePlWithoutItsNoise) {
  // GIVEN a GNSS/INS approval (tactical IMU), and its route flown by the simulator with that IMU
  // and tracked live
  const json doc = smallMission("ins_live", {{"navigation", {{"kind", "gnss_ins"}, {"imu", "tactical"}}}});
  auto approver = std::make_shared<Approver>(parsed(doc));
  const ApprovalReport r = approver->approve();
  ASSERT_TRUE(r.approved);
  Tracker tracker;
  tracker.addFlight("F1", parseApprovalReport(json(r), "report.json"), approver);
  test::ImuFeed imu;
  imu.grade = integrity::ins::ImuGrade::kTactical;
  std::vector<double> ratio_h, ratio_v;
  for (const test::SimulatedFix& sf : test::simulateRoute(r, *approver, {}, 5, 0.0, "F1", imu)) {
    for (const TrackEvent& e : tracker.process(sf.fix)) {
      const json j = e.toJson();
      if (j.at("event") != "fix" || j.value("pl_source", "") != "gnss_ins" || sf.t_s < 30.0) continue;
      // the predicted sample at the same time after departure
      const auto k = static_cast<std::size_t>(std::lround(sf.t_s / doc.at("integrity").value("sample_s", 1.0)));
      if (k >= r.predicted.size()) continue;
      ratio_h.push_back(j.at("hpl_m").get<double>() / r.predicted[k].hpl_m);
      ratio_v.push_back(j.at("vpl_m").get<double>() / r.predicted[k].vpl_m);
    }
  }
  // THEN the live fault-mode PLs are the predicted ones plus their innovation terms: the median
  // live/predicted ratio is close to 1 and never far below it
  ASSERT_GT(ratio_h.size(), 50u);
  for (std::vector<double>* v : {&ratio_h, &ratio_v}) {
    std::sort(v->begin(), v->end());
    const double median = (*v)[v->size() / 2];
    std::printf("live / predicted PL: min %.3f, median %.3f, max %.3f over %zu fixes\n", v->front(), median, v->back(),
                v->size());
    EXPECT_GT(median, 0.9);
    EXPECT_LT(median, 1.5);
    EXPECT_GT(v->front(), 0.8);
  }
}

TEST(InsPlPrediction, RefusesBadInputWithASentence) {
  InsPredictionInput in;
  in.duration_s = 10.0;
  const integrity::OrbitSource none;
  EXPECT_NE(test::messageOf<std::invalid_argument>([&] { (void)predictInsProtectionLevels(none, in); }).find("no route"),
            std::string::npos);
  in.where = [](double) { return maps::Geodetic{0.8, 0.15, 400.0}; };
  in.sample_t_s = {0.0, 5.0, 3.0};
  EXPECT_NE(test::messageOf<std::invalid_argument>([&] { (void)predictInsProtectionLevels(none, in); }).find("ascend"),
            std::string::npos);
}

}  // namespace
}  // namespace skylane::planner
