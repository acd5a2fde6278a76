// Live corridor tracking (issue 8): per-fix verdicts, persistence, monitoring reruns that exclude
// a faulty satellite of a simulated flight, replans from a drifted vehicle, immediate zone
// events, and NMEA / JSON-lines agreement.
#include "planner/tracking/tracker.hpp"

#include "planner/operational_intent.hpp"

#include "maps/parse_error.hpp"
#include "maps/json_node.hpp"
#include "maps/text_file.hpp"
#include "tests/planner/simulated_flight.hpp"
#include "tests/planner/track_events.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>

namespace skylane::planner {
namespace {

using nlohmann::json;

const std::string kExampleDir = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve";

/// The bundled example mission, with changes.
Mission exampleMission(const std::function<void(json&)>& edit = {}) {
  json doc = maps::readJsonFile(kExampleDir + "/mission.json");
  if (edit) edit(doc);
  return parseMission(doc, kExampleDir + "/mission.json", kExampleDir);
}

/// An approved flight and its approver; the report goes through its JSON form (writer → reader).
struct Approved {
  std::shared_ptr<Approver> approver;
  ApprovalReport report;
  ApprovedFlight flight;
};

Approved approveMission(Mission m) {
  Approved a;
  a.approver = std::make_shared<Approver>(std::move(m));
  a.report = a.approver->approve();
  EXPECT_TRUE(a.report.approved);
  a.flight = parseApprovalReport(nlohmann::json(a.report), "report.json");
  return a;
}

/// Position along the approved route t seconds after departure (map frame).
Eigen::Vector3d along(const ApprovalReport& r, double t) { return positionAlong(r.route, t); }

TrackFix fixAt(const Approver& a, const maps::GpsTime& t, const Eigen::Vector3d& p_map, double hpl, double vpl,
               std::size_t line) {
  TrackFix f;
  f.flight = "F1";
  f.time = t;
  const Eigen::Vector2d ll = a.frame().toLatLon(p_map.head<2>());
  f.lat_rad = ll.x();
  f.lon_rad = ll.y();
  f.h_ell_m = p_map.z();
  f.hpl_m = hpl;
  f.vpl_m = vpl;
  f.line = line;
  f.source = "test:" + std::to_string(line);
  return f;
}

using test::ofType;

/// The file's SHA-256 as coreutils' sha256sum prints it (an implementation independent of ours).
std::string sha256sum(const std::string& path) {
  std::string out;
  FILE* p = popen(("sha256sum '" + path + "'").c_str(), "r");
  if (!p) return out;
  char buf[65] = {};
  if (std::fread(buf, 1, 64, p) == 64) out.assign(buf, 64);
  pclose(p);
  return out;
}

/// The unit vector across the route's first segment (left of the direction of flight).
Eigen::Vector3d acrossFirstSegment(const ApprovalReport& r) {
  const Eigen::Vector2d d = (r.route[1].xyz - r.route[0].xyz).head<2>().normalized();
  return Eigen::Vector3d(-d.y(), d.x(), 0.0);
}

class TrackerOnExample : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { example_ = new Approved(approveMission(exampleMission())); }
  static void TearDownTestSuite() {
    delete example_;
    example_ = nullptr;
  }
  static Approved* example_;
};
Approved* TrackerOnExample::example_ = nullptr;

TEST_F(TrackerOnExample, TheReportsJsonFormReadsBackIntoTheFlightTrackingActsOn) {
  const ApprovalReport& r = example_->report;
  const json j = r;
  const ApprovedFlight f = j.get<ApprovedFlight>();  // from_json: the same reader as a report file
  EXPECT_TRUE(f.approved);
  EXPECT_EQ(f.mission_name, r.mission.name);
  EXPECT_EQ(f.mission_source, kExampleDir + "/mission.json");
  // The digest is of the mission file as the approver read it (an independent SHA-256 here).
  ASSERT_FALSE(r.mission.inputs.empty());
  EXPECT_EQ(r.mission.inputs.front().role, "mission");
  EXPECT_EQ(f.mission_sha256, sha256sum(kExampleDir + "/mission.json"));
  EXPECT_EQ(f.departure.week, r.departure.week);
  EXPECT_NEAR(f.departure.sow, r.departure.sow, 1e-9);
  ASSERT_EQ(f.route.size(), r.route.size());
  for (std::size_t i = 0; i < r.route.size(); ++i) {
    // One rounding rule: 1e-8° (≈ 1 mm) and the millimetre.
    EXPECT_NEAR(maps::rad2deg(f.route[i].lat_rad), maps::rad2deg(r.route[i].lat_rad), 0.51e-8);
    EXPECT_NEAR(maps::rad2deg(f.route[i].lon_rad), maps::rad2deg(r.route[i].lon_rad), 0.51e-8);
    EXPECT_NEAR(f.route[i].h_ell_m, r.route[i].h_ell_m, 0.51e-3);
    EXPECT_NEAR(f.route[i].eta_s, r.route[i].eta_s, 0.51e-3);
  }
  EXPECT_NEAR(f.level1.hal_m, r.limits.level1.hal_m, 0.51e-3);
  EXPECT_NEAR(f.level2.val_m, r.limits.level2.val_m, 0.51e-3);
  // A document that is not a report is refused by name.
  const json not_a_report = {{"decision", "maybe"}};
  EXPECT_THROW((void)not_a_report.get<ApprovedFlight>(), maps::ParseError);
}

TEST_F(TrackerOnExample, TheOperationalIntentReadsBackIntoTheSameVolumes) {
  const OperationalIntent oi = operationalIntent(example_->report, example_->approver->frame());
  ASSERT_EQ(oi.volumes.size(), example_->report.route.size() - 1);
  const json j = oi;
  const OperationalIntent back = j.get<OperationalIntent>();
  EXPECT_EQ(json(back), j);  // one form, read and written again
  ASSERT_EQ(back.volumes.size(), oi.volumes.size());
  for (std::size_t i = 0; i < oi.volumes.size(); ++i) {
    EXPECT_NEAR(back.volumes[i].altitude_lower_m, oi.volumes[i].altitude_lower_m, 0.51e-3);
    EXPECT_NEAR(back.volumes[i].time_end - oi.volumes[i].time_end, 0.0, 0.51);  // whole seconds
    EXPECT_NEAR(maps::rad2deg(back.volumes[i].outline_rad[0].x()), maps::rad2deg(oi.volumes[i].outline_rad[0].x()), 0.51e-8);
  }
  // A volume in feet or above mean sea level is not this form: refused by name.
  json feet = j;
  feet["operational_intent"]["volumes"][0]["volume"]["altitude_lower"]["units"] = "FT";
  EXPECT_THROW((void)feet.get<OperationalIntent>(), maps::ParseError);
}

TEST_F(TrackerOnExample, FixesOnTheRouteWithSmallPlsAreInsideEveryLevel) {
  Tracker tracker;
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  for (int k = 0; k < 20; ++k) {
    const auto ev = tracker.processJson(fixAt(*example_->approver, r.departure.plus(k), along(r, k), 0.5, 0.5, k + 1));
    ASSERT_EQ(ev.size(), 1u) << ev.front().dump();
    const json& fix = ev.back();
    EXPECT_EQ(fix.at("verdict"), "inside");
    // Level-1 margin: HAL₁ − (cross-track offset ≈ 0) − HPL, to the rounding of the route (mm).
    EXPECT_NEAR(fix.at("levels").at("level1").at("margin_h_m").get<double>(), r.limits.level1.hal_m - 0.5, 0.01);
    EXPECT_NEAR(fix.at("levels").at("level2").at("margin_h_m").get<double>(), r.limits.level2.hal_m - 0.5, 0.01);
  }
}

TEST_F(TrackerOnExample, JsonLineWritesTheSameEventAsTheJsonObject) {
  // GIVEN fixes inside, outside, near zones, and one whose note and flight need escaping
  TrackerOptions opt;
  opt.replan = false;
  opt.horizon_m = 500.0;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  tracker.addFlight("quote\"and\\back\tslash", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Eigen::Vector3d side = acrossFirstSegment(r);
  int fixes = 0;
  for (int k = 0; k < 60; ++k) {
    TrackFix f = fixAt(*example_->approver, r.departure.plus(k), along(r, 2 * k) + (k % 4) * side, 0.3 + 0.1 * (k % 7), 0.4, k + 1);
    if (k % 3 == 0) f.flight = "quote\"and\\back\tslash";
    for (const TrackEvent& e : tracker.process(f)) {
      // THEN the line parses to the very object toJson builds (members, numbers, nulls)
      EXPECT_EQ(json::parse(e.jsonLine()), e.toJson()) << e.jsonLine();
      // AND the JSON form reads back into an event that writes it again (from_json)
      EXPECT_EQ(e.toJson().get<TrackEvent>().toJson(), e.toJson()) << e.jsonLine();
      fixes += e.is("fix");
    }
  }
  EXPECT_EQ(fixes, 60);
}

TEST_F(TrackerOnExample, OneNoisyFixRaisesAViolationButNoReplan) {
  Tracker tracker;  // level 1: 3 of 5
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Eigen::Vector3d side = acrossFirstSegment(r);
  std::vector<json> all;
  for (int k = 0; k < 12; ++k) {
    Eigen::Vector3d p = along(r, k);
    if (k == 5) p += 3.0 * side;  // one fix 3 m off the centre line: outside HAL₁ = 1.44 m
    for (json& e : tracker.processJson(fixAt(*example_->approver, r.departure.plus(k), p, 0.5, 0.5, k + 1))) all.push_back(e);
  }
  const auto violations = ofType(all, "violation");
  ASSERT_EQ(violations.size(), 1u);
  EXPECT_EQ(violations[0].at("level"), "level1");
  EXPECT_EQ(violations[0].at("cause"), "position");
  EXPECT_EQ(violations[0].at("line"), 6);
  EXPECT_TRUE(ofType(all, "replan").empty());
  const auto recovered = ofType(all, "recovered");
  ASSERT_EQ(recovered.size(), 1u);
  EXPECT_EQ(recovered[0].at("line"), 8);  // two fixes in a row inside after the violation
}

TEST_F(TrackerOnExample, PersistentDriftReplansFromTheVehicleWithACorridorClearOfTheZones) {
  // GIVEN the vehicle drifting 8 m to the side of its corridor from t = 40 s on
  TrackerOptions opt;
  opt.level1_m = 3;
  opt.level1_n = 5;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Eigen::Vector3d side = acrossFirstSegment(r);
  std::vector<json> all;
  std::optional<json> replan;
  Eigen::Vector3d replan_from;
  for (int k = 0; k < 50 && !replan; ++k) {
    Eigen::Vector3d p = along(r, k);
    if (k >= 40) p += 8.0 * side;
    for (json& e : tracker.processJson(fixAt(*example_->approver, r.departure.plus(k), p, 0.5, 0.5, k + 1))) {
      if (e.at("event") == "replan") {
        replan = e;
        replan_from = p;
      }
      all.push_back(e);
    }
  }
  // THEN the third violated fix (3 of 5) replans, from where the vehicle is
  ASSERT_TRUE(replan);
  EXPECT_EQ(replan->at("line"), 43);
  EXPECT_EQ(replan->at("trigger"), "level1");
  ASSERT_EQ(replan->at("decision"), "approved") << replan->dump();
  EXPECT_EQ(replan->at("route_version"), 1);
  EXPECT_FALSE(replan->at("operational_intent").at("volumes").empty());
  const json& route = replan->at("report").at("route");
  const Eigen::Vector2d first = example_->approver->frame().toPlane(maps::deg2rad(route[0].at("lat").get<double>()),
                                                                     maps::deg2rad(route[0].at("lon").get<double>()));
  EXPECT_LT((first - replan_from.head<2>()).norm(), 0.01);
  // AND the new corridor (level-1 box along every new segment, sampled each metre) meets no
  // active counted zone: checked with the obstructions directly, not through the tracker.
  const geofence::Obstructions& ob = example_->approver->obstructions();
  std::vector<Eigen::Vector3d> pts;
  for (const json& p : route) {
    const Eigen::Vector2d xy = example_->approver->frame().toPlane(maps::deg2rad(p.at("lat").get<double>()),
                                                                    maps::deg2rad(p.at("lon").get<double>()));
    pts.emplace_back(xy.x(), xy.y(), p.at("h_ell_m").get<double>());
  }
  const maps::GpsTime t = r.departure.plus(42);
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double len = (pts[i] - pts[i - 1]).norm();
    for (double s = 0; s <= len; s += 1.0) {
      const Eigen::Vector3d p = pts[i - 1] + (s / len) * (pts[i] - pts[i - 1]);
      const auto c = ob.firstConflict({t, t, {p, r.limits.level1.hal_m, r.limits.level1.val_m}});
      if (c) {
        EXPECT_NE(c->level, geofence::Level::kZone) << "segment " << i << " at " << s << " m meets " << c->subject;
      }
    }
  }
  // AND the next fix at the drifted place is inside the new corridor
  const auto next = tracker.processJson(fixAt(*example_->approver, r.departure.plus(43), replan_from, 0.5, 0.5, 44));
  EXPECT_EQ(next.back().at("levels").at("level1").at("verdict"), "inside") << next.back().dump();
  EXPECT_EQ(next.back().at("route_version"), 1);
  // AND every event (fix, violation, monitoring_rerun, replan) reads back into the same JSON
  for (const json& e : all) EXPECT_EQ(e.get<TrackEvent>().toJson(), e) << e.dump();
}

/// Replans of a vehicle pushed 8 m aside by a 14 s gust (t = 40–53 s) that then flies on along
/// its approved route to t = 160 s: its autopilot never got a new route (no link).
int replansOfAVehicleThatIgnoresThem(const Approved& a, double join_timeout_s) {
  TrackerOptions opt;
  opt.join_timeout_s = join_timeout_s;
  Tracker tracker(opt);
  tracker.addFlight("F1", a.flight, a.approver);
  const ApprovalReport& r = a.report;
  const Eigen::Vector3d side = acrossFirstSegment(r);
  int replans = 0;
  for (int k = 0; k <= 160; ++k) {
    const Eigen::Vector3d p = along(r, k) + (k >= 40 && k < 54 ? 8.0 : 0.0) * side;
    for (const TrackEvent& e : tracker.process(fixAt(*a.approver, r.departure.plus(k), p, 0.5, 0.5, k + 1))) replans += e.is("replan");
  }
  return replans;
}

TEST_F(TrackerOnExample, AReplanWaitsForTheVehicleToJoinTheNewRouteOrForTheJoinTimeout) {
  // Without the wait (the 10 s cooldown alone) every new route is replanned again as soon as
  // the persistence window refills: the cascade of a vehicle that never got the route.
  const int cascade = replansOfAVehicleThatIgnoresThem(*example_, 0.0);
  const int damped = replansOfAVehicleThatIgnoresThem(*example_, 60.0);
  const int never = replansOfAVehicleThatIgnoresThem(*example_, 1e9);
  EXPECT_EQ(cascade, 5);
  EXPECT_EQ(damped, 3);
  // Waiting for ever, two remain: the pushed vehicle runs parallel to the first new route, which
  // starts where it was, for the five fixes that count as joining it; back on its old route it is
  // off the new one, and that persistent violation replans once more, onto the old route.
  EXPECT_EQ(never, 2);
}

TEST_F(TrackerOnExample, WithALinkTheReplanWaitsForTheVehiclesAnswer) {
  TrackerOptions opt;
  opt.handoff_by_link = true;
  opt.join_timeout_s = 1e9;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Eigen::Vector3d side = acrossFirstSegment(r);
  int replans = 0;
  std::string held_note;
  auto fly = [&](int from, int to) {
    for (int k = from; k <= to; ++k) {
      const Eigen::Vector3d p = along(r, k) + (k >= 40 ? 8.0 : 0.0) * side;
      for (const TrackEvent& e : tracker.process(fixAt(*example_->approver, r.departure.plus(k), p, 0.5, 0.5, k + 1))) {
        replans += e.is("replan");
        if (e.is("fix") && e.fix->note.find("replan held") != std::string::npos) held_note = e.fix->note;
      }
    }
  };
  fly(0, 80);
  EXPECT_EQ(replans, 1);
  EXPECT_NE(held_note.find("awaiting the link's answer"), std::string::npos) << held_note;
  // The vehicle refuses the upload: the hold ends, and the persistent violation replans again.
  tracker.handoffResult("F1", tracker.state("F1").route_version, false, r.departure.plus(80));
  fly(81, 100);
  EXPECT_EQ(replans, 2);
}

TEST_F(TrackerOnExample, ProtectionVolumeTouchingAProhibitedZoneIsReportedAtOnce) {
  TrackerOptions opt;
  opt.replan = false;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  // EX-ZH-HELIPORT: a circle of 250 m round (47.379 N, 8.538 E) from 0 to 300 m AGL.
  const maps::PlaneFrame& frame = example_->approver->frame();
  const Eigen::Vector2d c = frame.toPlane(maps::deg2rad(47.379), maps::deg2rad(8.538));
  const Eigen::Vector2d start = r.route.front().xyz.head<2>();
  const Eigen::Vector2d towards = (start - c).normalized();
  const double h = r.route.front().xyz.z();
  auto at = [&](double from_edge_m) {
    const Eigen::Vector2d p = c + towards * (250.0 + from_edge_m);
    return Eigen::Vector3d(p.x(), p.y(), h);
  };
  // 30 m from the edge with HPL 10 m: clear; the next fix, HPL 40 m: it touches.
  const auto clear = tracker.processJson(fixAt(*example_->approver, r.departure.plus(1), at(30.0), 10.0, 5.0, 1));
  EXPECT_TRUE(ofType(clear, "violation").empty() || ofType(clear, "violation")[0].at("level") != "zone");
  const auto touch = tracker.processJson(fixAt(*example_->approver, r.departure.plus(2), at(30.0), 40.0, 5.0, 2));
  const auto v = ofType(touch, "violation");
  const auto zone = std::find_if(v.begin(), v.end(), [](const json& e) { return e.at("level") == "zone"; });
  ASSERT_NE(zone, v.end());
  EXPECT_EQ(zone->at("subject"), "EX-ZH-HELIPORT");
  // The overlap is HPL − distance to the edge, 10 m, to the circle's projection allowance.
  EXPECT_NEAR(zone->at("margin_h_m").get<double>(), -10.0, 0.5);
  const json& near = touch.back().at("near");
  const auto in_near = std::find_if(near.begin(), near.end(), [](const json& n) { return n.at("subject") == "EX-ZH-HELIPORT"; });
  ASSERT_NE(in_near, near.end());
  EXPECT_EQ(in_near->at("verdict"), "met");  // a zone check: met, not "outside"
  EXPECT_EQ(in_near->at("restriction"), "PROHIBITED");
  EXPECT_EQ(zone->at("verdict"), "met");
  EXPECT_EQ(zone->at("restriction"), "PROHIBITED");
  EXPECT_EQ(in_near->at("clearance_m"), 0.0);
}

TEST_F(TrackerOnExample, BadOrderUnknownFlightsAndStaleFlightsAreReportedAndSkipped) {
  Tracker tracker;
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Approver& a = *example_->approver;
  EXPECT_EQ(ofType(tracker.processJson(fixAt(a, r.departure.plus(10), along(r, 10), 0.5, 0.5, 1)), "fix").size(), 1u);
  auto dup = tracker.processJson(fixAt(a, r.departure.plus(10), along(r, 10), 0.5, 0.5, 2));
  ASSERT_EQ(dup.size(), 1u);
  EXPECT_EQ(dup[0].at("event"), "rejected_input");
  EXPECT_NE(dup[0].at("error").get<std::string>().find("duplicate time"), std::string::npos);
  EXPECT_EQ(dup[0].get<TrackEvent>().toJson(), dup[0]);  // the JSON form reads back
  auto back = tracker.processJson(fixAt(a, r.departure.plus(9), along(r, 9), 0.5, 0.5, 3));
  EXPECT_NE(back[0].at("error").get<std::string>().find("out of order"), std::string::npos);
  auto jump = tracker.processJson(fixAt(a, r.departure.plus(4000), along(r, 20), 0.5, 0.5, 4));
  EXPECT_NE(jump[0].at("error").get<std::string>().find("time jump"), std::string::npos);
  // A lone jumped fix is refused; the later fixes on the old timeline are taken as before.
  TrackFix stranger = fixAt(a, r.departure.plus(11), along(r, 11), 0.5, 0.5, 5);
  stranger.flight = "F9";
  auto unknown = tracker.processJson(stranger);
  EXPECT_NE(unknown[0].at("error").get<std::string>().find("unknown flight \"F9\""), std::string::npos);
  EXPECT_EQ(unknown[0].at("flight"), "F9");  // the flight the line named, though unknown
  // A 6 s gap: the next fix first reports the flight stale (3 s), then is accepted.
  auto late = tracker.processJson(fixAt(a, r.departure.plus(16), along(r, 16), 0.5, 0.5, 6));
  ASSERT_EQ(ofType(late, "stale").size(), 1u);
  EXPECT_DOUBLE_EQ(ofType(late, "stale")[0].at("gap_s").get<double>(), 6.0);
  EXPECT_EQ(ofType(late, "fix").size(), 1u);
  EXPECT_EQ(tracker.state("F1").fixes, 2u);
}

TEST_F(TrackerOnExample, AJumpedTimelineIsTakenAfterThreeFixesInOrder) {
  TrackerOptions opt;
  opt.replan = false;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Approver& a = *example_->approver;
  auto feed = [&](double t, std::size_t line) {
    return tracker.processJson(fixAt(a, r.departure.plus(t), along(r, 5), 0.5, 0.5, line)).back();
  };
  feed(0, 1);
  feed(1, 2);
  // WHEN the receiver's clock jumps an hour ahead and stays there
  EXPECT_NE(feed(3601, 3).at("error").get<std::string>().find("1 of 3"), std::string::npos);
  EXPECT_NE(feed(3602, 4).at("error").get<std::string>().find("2 of 3"), std::string::npos);
  const json taken = feed(3603, 5);
  // THEN the third fix in order takes the new timeline, and it goes on from there
  EXPECT_EQ(taken.at("event"), "fix");
  EXPECT_NE(taken.at("note").get<std::string>().find("a new timeline after a time jump of 3602 s"), std::string::npos);
  EXPECT_EQ(feed(3604, 6).at("event"), "fix");
  EXPECT_NE(feed(2, 7).at("error").get<std::string>().find("1 of 3"), std::string::npos);  // the old time is now a jump back
}

TEST_F(TrackerOnExample, AFirstFixFarFromTheApprovedDepartureNeedsItsTimelineConfirmed) {
  TrackerOptions opt;
  opt.replan = false;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Approver& a = *example_->approver;
  // A bogus time a day ahead is refused and does not move stream time (no flight goes stale).
  const auto bogus = tracker.processJson(fixAt(a, r.departure.plus(86400), along(r, 0), 0.5, 0.5, 1));
  EXPECT_NE(bogus.back().at("error").get<std::string>().find("from the approved departure"), std::string::npos);
  EXPECT_FALSE(tracker.streamTime());
  // The flight's real first fix is taken.
  EXPECT_EQ(tracker.processJson(fixAt(a, r.departure.plus(1), along(r, 1), 0.5, 0.5, 2)).back().at("event"), "fix");
  EXPECT_DOUBLE_EQ(*tracker.streamTime() - r.departure, 1.0);
}

TEST_F(TrackerOnExample, PlSourceSaysWhereThePlsCameFrom) {
  Tracker tracker;
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const Approver& a = *example_->approver;
  // Onboard PLs with two pseudoranges (too few for a position): the onboard PLs are used.
  TrackFix f = fixAt(a, r.departure.plus(1), along(r, 1), 0.5, 0.5, 1);
  f.ranges = {{integrity::SatId{integrity::Constellation::kGps, 5}, 2.1e7, std::nullopt},
              {integrity::SatId{integrity::Constellation::kGps, 7}, 2.2e7, std::nullopt}};
  f.pl_source = PlSource::kRaw;
  const json fix = tracker.processJson(f).back();
  EXPECT_EQ(fix.at("pl_source"), "onboard");
  EXPECT_NE(fix.at("note").get<std::string>().find("raw pseudoranges gave no PL"), std::string::npos);
  // An INS block alone: the three-hypothesis nominal-INS PLs.
  TrackFix g = fixAt(a, r.departure.plus(2), along(r, 2), 0.5, 0.5, 2);
  g.hpl_m.reset();
  g.vpl_m.reset();
  g.ins = InsUncertainty{1, 0.05, 0.05, 0.1};
  const json ins = tracker.processJson(g).back();
  EXPECT_EQ(ins.at("pl_source"), "ins");
  EXPECT_NEAR(ins.at("hpl_m").get<double>(), insNominalPl(*g.ins).first, 1e-3);
}

TEST(TrackJsonLine, DeepNestingAndBadUtf8AreErrorsNotCrashes) {
  const std::string deep(100000, '[');
  const std::string msg = test::messageOf<maps::ParseError>([&] { (void)maps::parseJsonLine(deep, "fixes.jsonl:3"); });
  EXPECT_NE(msg.find("nested at most 32 levels"), std::string::npos) << msg;
  // A flight id with an overlong form and a surrogate: the line is still valid JSON.
  TrackEvent e;
  e.type = "fix";
  e.flight = std::string("F\xC0\xAF-\xED\xA0\x80");
  e.fix = FixRecord{};
  json parsed;
  EXPECT_NO_THROW(parsed = json::parse(e.jsonLine()));
  EXPECT_EQ(parsed.at("event"), "fix");
}

TEST_F(TrackerOnExample, AFlightAtItsGoalIsNotStaleAndTheOthersAre) {
  Tracker tracker;
  tracker.addFlight("F1", example_->flight, example_->approver);
  tracker.addFlight("F2", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  const double end = r.route.back().eta_s;
  // F1 flies to its goal and stops sending; F2 goes silent mid-route; a third flight's fixes
  // carry the stream time on.
  tracker.addFlight("F3", example_->flight, example_->approver);
  std::vector<json> all;
  for (int k = 0; k <= static_cast<int>(end); ++k) {
    for (const char* id : {"F1", "F3"}) {
      TrackFix f = fixAt(*example_->approver, r.departure.plus(k), along(r, k), 0.5, 0.5, k + 1);
      f.flight = id;
      for (json& e : tracker.processJson(f)) all.push_back(e);
    }
    if (k < 20) {
      TrackFix f = fixAt(*example_->approver, r.departure.plus(k), along(r, k), 0.5, 0.5, k + 1);
      f.flight = "F2";
      for (json& e : tracker.processJson(f)) all.push_back(e);
    }
  }
  for (int k = static_cast<int>(end) + 1; k < static_cast<int>(end) + 10; ++k) {
    TrackFix f = fixAt(*example_->approver, r.departure.plus(k), along(r, k), 0.5, 0.5, k + 1);
    f.flight = "F3";
    for (json& e : tracker.processJson(f)) all.push_back(e);
  }
  const auto stale = ofType(all, "stale");
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].at("flight"), "F2");
  EXPECT_TRUE(tracker.state("F1").arrived);
  EXPECT_TRUE(tracker.state("F3").arrived);
  EXPECT_FALSE(tracker.state("F2").arrived);
}

TEST_F(TrackerOnExample, OneVehiclesClockJumpDoesNotMakeTheOthersStale) {
  TrackerOptions opt;
  opt.replan = false;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  tracker.addFlight("F2", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  std::vector<json> all;
  auto feed = [&](const char* id, double t, int k) {
    TrackFix f = fixAt(*example_->approver, r.departure.plus(t), along(r, k), 0.5, 0.5, static_cast<std::size_t>(k + 1));
    f.flight = id;
    for (json& e : tracker.processJson(f)) all.push_back(e);
  };
  // GIVEN two flights reporting every second, F2's receiver clock an hour ahead from 10 s on
  for (int k = 0; k < 60; ++k) {
    feed("F1", k, k);
    feed("F2", k < 10 ? k : k + 3600.0, k);
  }
  // THEN F2's new timeline is taken and no flight is stale while both report
  EXPECT_EQ(tracker.state("F2").fixes, 58u);  // two refused before the jump is confirmed
  EXPECT_NEAR(tracker.state("F2").clock_offset_s, 3600.0, 1e-9);
  EXPECT_TRUE(ofType(all, "stale").empty()) << ofType(all, "stale")[0].dump();
  // AND when F1 goes silent, F2's fixes (on their own clock) still carry the stream time on
  for (int k = 60; k < 70; ++k) feed("F2", k + 3600.0, k);
  const auto stale = ofType(all, "stale");
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].at("flight"), "F1");
  EXPECT_NEAR(stale[0].at("gap_s").get<double>(), 4.0, 1e-9);
  // AND the offset is kept with the flight's state
  EXPECT_NEAR(parseFlightState(flightStateJson(tracker.state("F2")), "db").clock_offset_s, 3600.0, 1e-9);
}

TEST_F(TrackerOnExample, TakingAJumpedTimelineWithASweepDueIsNotStale) {
  TrackerOptions opt;
  opt.replan = false;
  Tracker tracker(opt);
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  auto feed = [&](double t, std::size_t line) {
    return tracker.processJson(fixAt(*example_->approver, r.departure.plus(t), along(r, 5), 0.5, 0.5, line));
  };
  feed(0, 1);
  feed(1, 2);
  feed(3602, 3);
  feed(3603, 4);
  // GIVEN a quiet-input sweep (as the CLI makes on a live input) that leaves a sweep due
  EXPECT_TRUE(tracker.sweepStale(r.departure.plus(1.5)).empty());
  // WHEN the third fix takes the new timeline
  const auto ev = tracker.processJson(fixAt(*example_->approver, r.departure.plus(3604), along(r, 5), 0.5, 0.5, 5));
  // THEN the flight is not reported stale by its own jump
  EXPECT_TRUE(ofType(ev, "stale").empty()) << ofType(ev, "stale")[0].dump();
  EXPECT_EQ(ev.back().at("event"), "fix");
  EXPECT_NEAR(tracker.state("F1").clock_offset_s, 3603.0, 1e-9);
}

// --- NMEA and JSON lines give the same verdicts ---------------------------------------------

TEST_F(TrackerOnExample, NmeaAndJsonLinesGiveTheSameVerdicts) {
  const ApprovalReport& r = example_->report;
  const Eigen::Vector3d side = acrossFirstSegment(r);
  const NmeaPlRisk risk;
  const double k_h = std::sqrt(-2.0 * std::log(risk.p_h));
  const double k_v = 5.3342;  // Q⁻¹(4.9e-8), from a normal table
  int compared = 0;
  // The same fixes through two trackers: JSON lines with the PLs of the NMEA rule, and NMEA
  // sentences (RMC for the date, GGA, GST) built from them.
  TrackerOptions opt;
  opt.replan = false;  // verdicts only
  Tracker a(opt), b(opt);
  a.addFlight("F1", example_->flight, example_->approver);
  b.addFlight("F1", example_->flight, example_->approver);
  integrity::NmeaEpochAssembler asm2;
  std::vector<json> va, vb;
  for (int k = 0; k < 30; ++k) {
    const double off = (k % 7) * 0.25;
    const double sigma_h = 0.05 + 0.02 * (k % 5), sigma_v = 0.08 + 0.01 * (k % 3);
    const Eigen::Vector3d p = along(r, 2 * k) + off * side;
    const maps::GpsTime t = r.departure.plus(2 * k);
    TrackFix jf = fixAt(*example_->approver, t, p, k_h * sigma_h, k_v * sigma_v, static_cast<std::size_t>(k + 1));
    for (const json& e : a.processJson(jf)) {
      if (e.at("event") == "fix") va.push_back(e);
    }
    const maps::CalendarTime c = maps::utcFromGps(t);
    char hms[16];
    std::snprintf(hms, sizeof hms, "%02d%02d%05.2f", c.hour, c.minute, c.second);
    char tail[96];
    std::snprintf(tail, sizeof tail, ",4,12,0.8,%.4f,M,47.35,M,,", p.z() - 47.35);
    const Eigen::Vector2d q = example_->approver->frame().toLatLon(p.head<2>());
    const std::string gga = test::nmeaSentence("GPGGA," + std::string(hms) + "," + test::nmeaAngle(maps::rad2deg(q.x()), true) + "," +
                                            test::nmeaAngle(maps::rad2deg(q.y()), false) + tail);
    char gst[96];
    std::snprintf(gst, sizeof gst, "GPGST,%s,0.5,%.4f,%.4f,0.0,%.4f,%.4f,%.4f", hms, sigma_h, sigma_h * 0.8, sigma_h * 0.8,
                  sigma_h * 0.6, sigma_v);
    char rmc_date[8];
    std::snprintf(rmc_date, sizeof rmc_date, "%02d%02d%02d", c.day, c.month, c.year % 100);
    const std::string rmc = test::nmeaSentence("GPRMC," + std::string(hms) + ",A,4722.0000,N,00832.0000,E,0.0,0.0," + rmc_date + ",,,A");
    for (const std::string& s : {rmc, gga, test::nmeaSentence(gst)}) {
      if (auto nf = asm2.add(integrity::parseNmeaSentence(s, "fixes.nmea"))) {
        for (const json& e : b.processJson(trackFixFromNmea(*nf, "fixes.nmea"))) {
          if (e.at("event") == "fix") vb.push_back(e);
        }
      }
    }
  }
  if (auto nf = asm2.flush()) {
    for (const json& e : b.processJson(trackFixFromNmea(*nf, "fixes.nmea"))) {
      if (e.at("event") == "fix") vb.push_back(e);
    }
  }
  ASSERT_EQ(va.size(), 30u);
  ASSERT_EQ(vb.size(), 30u);
  int outside = 0;
  for (std::size_t i = 0; i < va.size(); ++i) {
    EXPECT_EQ(va[i].at("verdict"), vb[i].at("verdict")) << i;
    EXPECT_EQ(va[i].at("violated"), vb[i].at("violated")) << i;
    for (const char* level : {"level1", "level2"}) {
      EXPECT_NEAR(va[i]["levels"][level]["margin_h_m"].get<double>(), vb[i]["levels"][level]["margin_h_m"].get<double>(), 0.002)
          << i << " " << level;
      EXPECT_NEAR(va[i]["levels"][level]["margin_v_m"].get<double>(), vb[i]["levels"][level]["margin_v_m"].get<double>(), 0.002)
          << i << " " << level;
    }
    outside += va[i].at("verdict") != "inside";
    ++compared;
  }
  EXPECT_GT(outside, 3);   // the table exercises both verdicts
  EXPECT_LT(outside, 27);
  EXPECT_EQ(compared, 30);
}

// --- a simulated flight with a satellite fault: the rerun excludes it -----------------------

TEST_F(TrackerOnExample, RawFixesWhosePlNeverFitsHal1RerunOnceAndAreNotReplanned) {
  // GIVEN the bundled example (HAL₁ = 1.44 m) flown by the simulator without a fault: RAIM's
  // fault-free HPL (≈ 12 m) never fits the corridor
  Tracker tracker;
  tracker.addFlight("F1", example_->flight, example_->approver);
  const ApprovalReport& r = example_->report;
  std::vector<json> all;
  for (const test::SimulatedFix& sf : test::simulateRoute(r, *example_->approver, {}, 5)) {
    if (sf.fix.line > 40) break;
    for (json& e : tracker.processJson(sf.fix)) all.push_back(e);
  }
  // THEN one violation by the PL and one rerun event, every fix rerun and outside level 1,
  // and no replan (a corridor of the same width cannot hold the PL)
  ASSERT_EQ(ofType(all, "violation").size(), 1u);
  EXPECT_EQ(ofType(all, "violation")[0].at("cause"), "protection_level");
  EXPECT_EQ(ofType(all, "monitoring_rerun").size(), 1u);
  EXPECT_TRUE(ofType(all, "replan").empty());
  const auto fixes = ofType(all, "fix");
  ASSERT_EQ(fixes.size(), 40u);
  for (const json& fix : fixes) {
    EXPECT_EQ(fix.at("pl_source"), "raw");
    EXPECT_TRUE(fix.value("rerun", false));
    EXPECT_GT(fix.at("hpl_m").get<double>(), r.limits.level1.hal_m);
    EXPECT_EQ(fix.at("levels").at("level1").at("verdict"), "outside");
    EXPECT_EQ(fix.at("levels").at("level2").at("verdict"), "inside");
  }
}

/// A step of `bias_m` on the satellite in the middle of those in view (in id order) over [t0, t1).
integrity::sim::FaultSpec satelliteStep(double bias_m, double t0, double t1) {
  integrity::sim::FaultSpec f;
  f.target = integrity::sim::FaultTarget::kSatellite;
  f.pick = 0.5;
  f.t_start_s = t0;
  f.t_end_s = t1;
  f.magnitude = bias_m;
  return f;
}

TEST(TrackerRaw, SatelliteFaultIsExcludedByTheRerunAndTheFlightRecoversWithoutAReplan) {
  // GIVEN a large UAV (20 m span, 25 m long: HAL₁ = 24 m, VAL₁ = 30 m) on the example route, so
  // that fault-free RAIM PLs (≈ 12–13 m here) fit level 1
  Approved a = approveMission(exampleMission([](json& doc) {
    doc["vehicle"]["lateral_m"] = 20.0;
    doc["vehicle"]["longitudinal_m"] = 25.0;
    doc["k2"] = 100;
  }));
  ASSERT_NEAR(a.report.limits.level1.hal_m, 24.0, 1e-9);
  Tracker tracker;
  tracker.addFlight("F1", a.flight, a.approver);
  // AND the GNSS/INS simulator flying that route, with a 60 m step on one satellite from 60 s to 120 s
  const ApprovalReport& r = a.report;
  const integrity::sim::FaultSpec fault = satelliteStep(60.0, 60.0, 120.0);
  int reruns = 0, in_fault = 0, before = 0;
  std::vector<json> all;
  // (the reported height is 5 m off: it only starts skylane's own solution)
  for (const test::SimulatedFix& sf : test::simulateRoute(r, *a.approver, {fault}, 11, 5.0)) {
    const TrackFix& f = sf.fix;
    const std::optional<integrity::SatId>& faulty = sf.faulty;
    const auto ev = tracker.processJson(f);
    ASSERT_FALSE(ev.empty());
    const json& fix = ev.back();
    ASSERT_EQ(fix.at("event"), "fix") << fix.dump();
    for (const json& e : ev) all.push_back(e);
    const auto rr = ofType(ev, "monitoring_rerun");
    if (faulty) {
      ++in_fault;
      // THEN the first pass's PL leaves level 1, the rerun excludes the faulty satellite and the
      // PL after it fits again
      ASSERT_EQ(rr.size(), 1u) << "t = " << sf.t_s << ": " << fix.dump();
      ASSERT_EQ(rr[0].at("excluded").size(), 1u);
      EXPECT_EQ(rr[0].at("excluded")[0], faulty->str());
      EXPECT_GT(rr[0].at("hpl_before_m").get<double>(), 24.0);
      EXPECT_LT(rr[0].at("hpl_after_m").get<double>(), 24.0);
      EXPECT_EQ(rr[0].at("verdict_after"), "inside");
      ++reruns;
    } else {
      ++before;
      EXPECT_TRUE(rr.empty()) << "t = " << sf.t_s << ": " << rr[0].dump();
    }
    EXPECT_EQ(fix.at("verdict"), "inside") << "t = " << sf.t_s << ": " << fix.dump();
  }
  EXPECT_GE(in_fault, 59);
  EXPECT_EQ(reruns, in_fault);
  EXPECT_GT(before, 100);
  EXPECT_TRUE(ofType(all, "replan").empty());
  EXPECT_TRUE(ofType(all, "violation").empty());
}

// --- GNSS/INS: IMU increments with the pseudoranges (the fault-mode flow) --------------------------

/// A UAV whose corridor (HAL₁ = 48 m) holds the fault-mode PLs (≈ 15 m, ≈ 25 m with a
/// satellite excluded) and the simulator's corner cutting (30 m turn radius).
Approved largeUav() {
  Approved a = approveMission(exampleMission([](json& doc) {
    doc["vehicle"]["lateral_m"] = 40.0;
    doc["vehicle"]["longitudinal_m"] = 50.0;
    doc["k2"] = 100;
  }));
  EXPECT_NEAR(a.report.limits.level1.hal_m, 48.0, 1e-9);
  return a;
}

/// Horizontal and vertical distance of a fix event's position from the truth.
std::pair<double, double> fixError(const json& fix, const maps::Geodetic& truth) {
  const maps::LocalFrame enu(truth);
  const Eigen::Vector3d d = enu.toEnu({maps::deg2rad(fix.at("lat").get<double>()), maps::deg2rad(fix.at("lon").get<double>()),
                                       fix.at("h_ell_m").get<double>()});
  return {d.head<2>().norm(), std::abs(d.z())};
}

/// Whether a fix event's PLs bound its position's error (HPE ≤ HPL and VPE ≤ VPL).
bool plsBound(const json& fix, const maps::Geodetic& truth) {
  const auto [eh, ev] = fixError(fix, truth);
  return eh <= fix.at("hpl_m").get<double>() && ev <= fix.at("vpl_m").get<double>();
}

/// One simulated fix through the tracker, with its events (the `fix` event last).
struct TrackedFix {
  test::SimulatedFix sim;
  std::vector<json> events;
  [[nodiscard]] const json& fix() const { return events.back(); }
};

/// `a`'s route flown by the simulator with a tactical IMU, barometer and magnetometer (`faults`,
/// `seed`; `edit` may change each fix first) and tracked by a new tracker. Every fix must give a
/// `fix` event, and the stream's fast writer must give the same object as toJson.
std::vector<TrackedFix> trackGnssIns(const Approved& a, const std::vector<integrity::sim::FaultSpec>& faults, std::uint64_t seed,
                                     const std::function<void(test::SimulatedFix&)>& edit = {}) {
  Tracker tracker;
  tracker.addFlight("F1", a.flight, a.approver);
  std::vector<TrackedFix> out;
  for (test::SimulatedFix& sf : test::simulateRoute(a.report, *a.approver, faults, seed, 5.0, "F1", test::ImuFeed{})) {
    if (edit) edit(sf);
    TrackedFix t;
    for (const TrackEvent& e : tracker.process(sf.fix)) {
      t.events.push_back(e.toJson());
      if (e.fix) {
        EXPECT_EQ(json::parse(e.jsonLine()), t.events.back());
      }
    }
    EXPECT_FALSE(t.events.empty());
    if (t.events.empty() || t.fix().at("event") != "fix") {
      ADD_FAILURE() << "line " << sf.fix.line << " gave no fix event";
      continue;
    }
    t.sim = std::move(sf);
    out.push_back(std::move(t));
  }
  return out;
}

/// The events of a replay, in order.
std::vector<json> allEvents(const std::vector<TrackedFix>& replay) {
  std::vector<json> out;
  for (const TrackedFix& t : replay) out.insert(out.end(), t.events.begin(), t.events.end());
  return out;
}

TEST(TrackerGnssIns, FixesWithImuIncrementsUseTheFaultModeFlowAndItsPlsBoundTheError) {
  // GIVEN the large UAV flown by the simulator with a tactical IMU, barometer and magnetometer
  const Approved a = largeUav();
  const std::vector<TrackedFix> replay = trackGnssIns(a, {}, 21);
  ASSERT_GT(replay.size(), 100u);
  int ins = 0, bounded = 0;
  for (const TrackedFix& t : replay) {
    const json& fix = t.fix();
    if (t.sim.fix.line == 1) {
      // THEN the first fix aligns the filter and is solved as a snapshot
      EXPECT_EQ(fix.at("pl_source"), "raw");
      EXPECT_NE(fix.value("note", "").find("GNSS/INS aligned"), std::string::npos) << fix.dump();
      continue;
    }
    // AND every later fix comes from the GNSS/INS flow, and its PLs bound the true error
    ASSERT_EQ(fix.at("pl_source"), "gnss_ins") << fix.dump();
    EXPECT_FALSE(fix.at("ins_degraded").get<bool>());
    ++ins;
    bounded += plsBound(fix, t.sim.truth);
    EXPECT_EQ(fix.at("verdict"), "inside") << fix.dump();
  }
  EXPECT_EQ(bounded, ins);
  const std::vector<json> all = allEvents(replay);
  EXPECT_TRUE(ofType(all, "violation").empty());
  EXPECT_TRUE(ofType(all, "replan").empty());
}

TEST(TrackerGnssIns, ASatelliteFaultIsExcludedByTheFlowAndTheErrorStaysBounded) {
  // GIVEN the same flight with a 60 m step on one satellite from 60 s to 120 s
  const Approved a = largeUav();
  const std::vector<TrackedFix> replay = trackGnssIns(a, {satelliteStep(60.0, 60.0, 120.0)}, 23);
  int in_fault = 0, excluded_faulty = 0, excluded_other = 0, fixes = 0, bounded = 0;
  for (const TrackedFix& t : replay) {
    const json& fix = t.fix();
    if (t.sim.fix.line == 1) continue;
    ASSERT_EQ(fix.at("pl_source"), "gnss_ins") << fix.dump();
    ++fixes;
    const json ex = fix.value("excluded", json::array());
    if (t.sim.faulty) {
      ++in_fault;
      // THEN step 1's FDE leaves the faulty satellite out
      if (ex.size() == 1 && ex[0] == t.sim.faulty->str()) ++excluded_faulty;
    } else {
      excluded_other += static_cast<int>(ex.size());
    }
    bounded += plsBound(fix, t.sim.truth);
    EXPECT_EQ(fix.at("verdict"), "inside") << fix.dump();
  }
  EXPECT_GE(in_fault, 59);
  EXPECT_EQ(excluded_faulty, in_fault);
  EXPECT_LE(excluded_other, 2);  // false exclusions: P_FA per epoch, with some margin
  // AND the PLs bound the error at every fix, without a violation or a replan
  EXPECT_EQ(bounded, fixes);
  const std::vector<json> all = allEvents(replay);
  EXPECT_TRUE(ofType(all, "violation").empty());
  EXPECT_TRUE(ofType(all, "replan").empty());
}

TEST(TrackerGnssIns, TwoSatelliteFaultsAreExcludedByTheRerunWithOneMoreExclusion) {
  // GIVEN 60 m steps on two satellites at once from 40 s to 150 s (step 1 of the flow may
  // exclude one: it detects a fault it cannot exclude)
  const Approved a = largeUav();
  integrity::sim::FaultSpec second = satelliteStep(60.0, 40.0, 150.0);
  second.pick = 0.1;
  int in_fault = 0, both_excluded = 0, snapshot = 0, fixes = 0, bounded = 0, reruns = 0;
  for (const TrackedFix& t : trackGnssIns(a, {satelliteStep(60.0, 40.0, 150.0), second}, 33)) {
    const json& fix = t.fix();
    const test::SimulatedFix& sf = t.sim;
    reruns += static_cast<int>(ofType(t.events, "monitoring_rerun").size());
    if (sf.fix.line == 1) continue;
    // THEN the fixes stay on the GNSS/INS flow, the rerun leaving both satellites out (or, where
    // the remaining geometry cannot tell, the snapshot's grown PL_det stands)
    ++fixes;
    if (sf.t_s >= 40.0 && sf.t_s < 150.0) {
      ++in_fault;
      both_excluded += fix.at("pl_source") == "gnss_ins" && fix.value("excluded", json::array()).size() == 2;
      if (fix.at("pl_source") != "gnss_ins") {
        ++snapshot;
        EXPECT_TRUE(fix.at("fault_detected").get<bool>()) << fix.dump();
      }
    } else {
      ASSERT_EQ(fix.at("pl_source"), "gnss_ins") << fix.dump();
      EXPECT_EQ(fix.at("verdict"), "inside") << fix.dump();
    }
    bounded += plsBound(fix, sf.truth);
  }
  EXPECT_GE(in_fault, 109);
  EXPECT_GE(both_excluded, in_fault * 9 / 10) << snapshot << " snapshot fixes";
  ::testing::Test::RecordProperty("snapshot_fixes", snapshot);
  ::testing::Test::RecordProperty("both_excluded", both_excluded);
  EXPECT_GE(reruns, in_fault / 2);
  // AND the PLs bound the error at every fix
  EXPECT_EQ(bounded, fixes);
}

TEST(TrackerGnssIns, AnAccelerometerFaultDegradesToGnssAloneAndTheErrorStaysBounded) {
  // GIVEN an accelerometer step of 0.5 m/s² on the up axis from 60 s to 200 s
  const Approved a = largeUav();
  integrity::sim::FaultSpec fault;
  fault.target = integrity::sim::FaultTarget::kAccelerometer;
  fault.axis = 2;
  fault.t_start_s = 60.0;
  fault.t_end_s = 200.0;
  fault.magnitude = 0.5;
  int degraded = 0, fixes = 0, bounded = 0;
  for (const TrackedFix& t : trackGnssIns(a, {fault}, 25)) {
    const json& fix = t.fix();
    const test::SimulatedFix& sf = t.sim;
    if (sf.fix.line == 1) continue;
    ++fixes;
    if (fix.value("ins_degraded", false)) {
      ++degraded;
      // THEN the IMU innovation test sends the flow to GNSS alone (fault-mode class 1)
      EXPECT_GE(sf.t_s, 60.0);
    }
    bounded += plsBound(fix, sf.truth);
  }
  EXPECT_GT(degraded, 60);
  // AND the PLs bound the error throughout
  EXPECT_EQ(bounded, fixes);
}

TEST(TrackerGnssIns, MonteCarloWithRandomFaultsHasNoMisleadingFix) {
  // GIVEN 100 simulated flights, each with a random fault: none, a satellite step (10–100 m) or
  // ramp (0.5–3 m/s), an accelerometer step (0.1–1 m/s²) or a gyro step (0.001–0.01 rad/s), at a
  // random time, on a random satellite or axis
  const Approved a = largeUav();
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int fixes = 0, misleading = 0, ins = 0;
  for (int flight = 0; flight < 100; ++flight) {
    std::vector<integrity::sim::FaultSpec> faults;
    const int kind = flight % 5;
    if (kind > 0) {
      integrity::sim::FaultSpec f;
      f.t_start_s = 20.0 + 80.0 * u(rng);
      f.t_end_s = f.t_start_s + 30.0 + 60.0 * u(rng);
      f.pick = u(rng);
      f.axis = static_cast<int>(3.0 * u(rng)) % 3;
      if (kind == 1) {
        f.magnitude = 10.0 + 90.0 * u(rng);
      } else if (kind == 2) {
        f.ramp = true;
        f.magnitude = 0.5 + 2.5 * u(rng);
      } else if (kind == 3) {
        f.target = integrity::sim::FaultTarget::kAccelerometer;
        f.magnitude = 0.1 + 0.9 * u(rng);
      } else {
        f.target = integrity::sim::FaultTarget::kGyro;
        f.magnitude = 0.001 + 0.009 * u(rng);
      }
      faults.push_back(f);
    }
    for (const TrackedFix& t : trackGnssIns(a, faults, 1000 + static_cast<std::uint64_t>(flight))) {
      const json& fix = t.fix();
      const test::SimulatedFix& sf = t.sim;
      ++fixes;
      ins += fix.at("pl_source") == "gnss_ins";
      const auto [eh, ev] = fixError(fix, sf.truth);
      // THEN no fix's position is farther from the truth than its protection levels
      if (eh > fix.at("hpl_m").get<double>() || ev > fix.at("vpl_m").get<double>()) {
        ++misleading;
        ADD_FAILURE() << "flight " << flight << " t = " << sf.t_s << " s: error " << eh << " / " << ev << " m: " << fix.dump();
      }
    }
  }
  EXPECT_GT(fixes, 15000);
  EXPECT_GT(ins, fixes * 9 / 10);
  EXPECT_EQ(misleading, 0);
  ::testing::Test::RecordProperty("fixes", fixes);
}

TEST(TrackerGnssIns, SimulatedFixesWrittenAsJsonLinesReadBackTheSame) {
  // GIVEN a simulated GNSS/INS flight (turns, climbs, a satellite fault)
  const Approved a = largeUav();
  integrity::sim::FaultSpec fault;
  fault.pick = 0.3;
  fault.t_start_s = 30.0;
  fault.t_end_s = 60.0;
  fault.magnitude = 40.0;
  const auto flight = test::simulateRoute(a.report, *a.approver, {fault}, 31, 0.0, "F1", test::ImuFeed{});
  for (const test::SimulatedFix& sf : flight) {
    // WHEN each fix is written as a JSON line (skylane fly) and read back (skylane track)
    const TrackFix& f = sf.fix;
    const TrackFix g = parseTrackFixJson(json::parse(trackFixJson(f).dump()), "fly.jsonl:" + std::to_string(f.line));
    // THEN it is the same fix, to the writer's rounding
    ASSERT_EQ(g.flight, f.flight);
    ASSERT_NEAR(g.time - f.time, 0.0, 5e-4);
    ASSERT_NEAR(g.lat_rad, f.lat_rad, 1e-10);
    ASSERT_NEAR(g.h_ell_m, f.h_ell_m, 1e-4);
    ASSERT_EQ(g.ranges.size(), f.ranges.size());
    for (std::size_t i = 0; i < f.ranges.size(); ++i) {
      ASSERT_EQ(g.ranges[i].sat, f.ranges[i].sat);
      ASSERT_NEAR(g.ranges[i].pr_m, f.ranges[i].pr_m, 1e-4);
      ASSERT_LT((*g.ranges[i].sat_ecef_m - *f.ranges[i].sat_ecef_m).norm(), 1e-4);
    }
    ASSERT_TRUE(g.imu);
    ASSERT_EQ(g.imu->increments.size(), f.imu->increments.size());
    for (std::size_t i = 0; i < f.imu->increments.size(); ++i) {
      ASSERT_EQ(g.imu->increments[i].dtheta_rad, f.imu->increments[i].dtheta_rad);
      ASSERT_EQ(g.imu->increments[i].dv_mps, f.imu->increments[i].dv_mps);
    }
    ASSERT_LT((*g.attitude_rad - *f.attitude_rad).norm(), 1e-7);
    ASSERT_LT((*g.velocity_enu_mps - *f.velocity_enu_mps).norm(), 1e-4);
    ASSERT_NEAR(*g.baro_h_m, *f.baro_h_m, 1e-4);
  }
}

TEST(TrackerGnssIns, AWrongBarometerIsRefusedAndTheErrorStaysBounded) {
  // GIVEN a flight whose barometer reads 500 m high from 50 s on
  const Approved a = largeUav();
  int refused = 0, wrong = 0, fixes = 0, bounded = 0;
  const auto high = [](test::SimulatedFix& sf) {
    if (sf.t_s >= 50.0) *sf.fix.baro_h_m += 500.0;
  };
  for (const TrackedFix& t : trackGnssIns(a, {}, 35, high)) {
    const json& fix = t.fix();
    const test::SimulatedFix& sf = t.sim;
    if (sf.fix.line == 1) continue;
    ++fixes;
    wrong += sf.t_s >= 50.0;
    // THEN the filter's innovation gate refuses every such reading and says so
    if (fix.value("note", "").find("refused the barometer") != std::string::npos) ++refused;
    bounded += plsBound(fix, sf.truth);
    EXPECT_EQ(fix.at("pl_source"), "gnss_ins");
  }
  EXPECT_GT(fixes, 150);
  EXPECT_EQ(refused, wrong);
  // AND the PLs bound the error at every fix
  EXPECT_EQ(bounded, fixes);
}

TEST(TrackerGnssIns, ALostFixOrARestartAlignsTheFilterAgain) {
  const Approved a = largeUav();
  const auto flight = test::simulateRoute(a.report, *a.approver, {}, 27, 5.0, "F1", test::ImuFeed{});
  ASSERT_GT(flight.size(), 60u);
  Tracker tracker;
  tracker.addFlight("F1", a.flight, a.approver);
  std::vector<json> fixes;
  for (std::size_t i = 0; i < 40; ++i) {
    if (i == 20) continue;  // GIVEN one line lost: the next fix's increments cover 1 s of 2
    fixes.push_back(tracker.processJson(flight[i].fix).back());
  }
  // THEN the fix after the gap is a snapshot that aligns again, and the next is GNSS/INS
  EXPECT_EQ(fixes[19].at("pl_source"), "gnss_ins");
  EXPECT_EQ(fixes[20].at("pl_source"), "raw");
  EXPECT_NE(fixes[20].value("note", "").find("the filter aligns again"), std::string::npos) << fixes[20].dump();
  EXPECT_EQ(fixes[21].at("pl_source"), "gnss_ins") << fixes[21].dump();
  // AND a restarted tracker (state restored, no filter) aligns at its first fix
  Tracker restarted;
  restarted.addFlight("F1", a.flight, a.approver);
  restarted.restore("F1", tracker.state("F1"), tracker.routeJson("F1"));
  const json r1 = restarted.processJson(flight[40].fix).back();
  const json r2 = restarted.processJson(flight[41].fix).back();
  EXPECT_EQ(r1.at("pl_source"), "raw");
  EXPECT_NE(r1.value("note", "").find("GNSS/INS aligned"), std::string::npos) << r1.dump();
  EXPECT_EQ(r2.at("pl_source"), "gnss_ins");
  EXPECT_EQ(restarted.state("F1").fixes, tracker.state("F1").fixes + 2);
}

// --- parsing ----------------------------------------------------------------------------------

TEST(TrackFixJson, ErrorsNameTheFieldAndWhatWasExpected) {
  auto err = [](const std::string& text) {
    try {
      (void)parseTrackFixJson(json::parse(text), "fixes.jsonl:7");
    } catch (const maps::ParseError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string base = R"("time":"2020-01-01T14:00:00Z","lat":47.3,"lon":8.5,"h_ell_m":500)";
  EXPECT_NE(err("{" + base + "}").find("a protection level"), std::string::npos);
  EXPECT_NE(err("{" + base + R"(,"hpl_m":1})").find("both hpl_m and vpl_m"), std::string::npos);
  EXPECT_NE(err("{" + base + R"(,"hpl_m":-1,"vpl_m":1})").find("$.hpl_m"), std::string::npos);
  EXPECT_NE(err("{" + base + R"(,"hpl_m":1,"vpl_m":1,"speed":3})").find("$.speed"), std::string::npos);
  EXPECT_NE(err(R"({"time":"yesterday","lat":47.3,"lon":8.5,"h_ell_m":500,"hpl_m":1,"vpl_m":1})").find("RFC 3339"), std::string::npos);
  EXPECT_NE(err("{" + base + R"(,"pseudoranges":[{"sat":"X99","pr_m":2.1e7}]})").find("$.pseudoranges[0].sat"), std::string::npos);
  EXPECT_NE(err("{" + base + R"(,"imu":{"grade":"toy","sigma_n_m":1,"sigma_e_m":1,"sigma_u_m":1}})").find("aviation, tactical or consumer"),
            std::string::npos);
  EXPECT_NE(err("{" + base + "}").find("fixes.jsonl:7"), std::string::npos);
  // IMU increments: seven numbers each, a positive interval, with pseudoranges or onboard PLs
  const std::string pr = R"(,"hpl_m":1,"vpl_m":1)";
  EXPECT_NE(err("{" + base + pr + R"(,"imu":{"grade":"tactical","increments":[[0.01,0,0,0,0,0]]}})").find("$.imu.increments[0]"),
            std::string::npos);
  EXPECT_NE(err("{" + base + pr + R"(,"imu":{"grade":"tactical","increments":[[0,0,0,0,0,0,0]]}})").find("(0, 1] s"),
            std::string::npos);
  EXPECT_NE(err("{" + base + pr + R"(,"imu":{"grade":"tactical","increments":[[0.01,1,0,0,0,0,0]]}})").find("35 rad/s"),
            std::string::npos);
  EXPECT_NE(err("{" + base + pr + R"(,"imu":{"grade":"tactical","increments":[]}})").find("1 to 10,000"), std::string::npos);
  EXPECT_NE(err("{" + base + pr + R"(,"imu":{"grade":"tactical","sigma_n_m":1,"increments":[[0.01,0,0,0,0,0,0]]}})")
                .find("not both"),
            std::string::npos);
  EXPECT_NE(err("{" + base + R"(,"imu":{"grade":"tactical","increments":[[0.01,0,0,0,0,0,0]]}})").find("pseudoranges with the IMU"),
            std::string::npos);
  EXPECT_NE(err("{" + base + pr + R"(,"attitude_deg":{"roll":0,"pitch":95,"heading":0}})").find("$.attitude_deg.pitch"),
            std::string::npos);
  EXPECT_NE(err("{" + base + pr + R"(,"velocity_enu_mps":[1,2]})").find("[ve, vn, vu]"), std::string::npos);
  const TrackFix imu = parseTrackFixJson(
      json::parse("{" + base + pr +
                  R"(,"imu":{"grade":"aviation","increments":[[0.01,0.001,0,0,0,0,0.0981],[0.02,0,0,0,0,0,0.1962]]},)"
                  R"("velocity_enu_mps":[1,2,3],"attitude_deg":{"roll":1,"pitch":2,"heading":90},"mag_heading_deg":91})"),
      "x");
  ASSERT_TRUE(imu.imu);
  EXPECT_EQ(imu.imu->grade, 0);
  EXPECT_NEAR(imu.imu->span_s(), 0.03, 1e-12);
  EXPECT_DOUBLE_EQ(imu.imu->increments[1].dv_mps.z(), 0.1962);
  EXPECT_NEAR(imu.attitude_rad->z(), M_PI / 2.0, 1e-12);
  EXPECT_NEAR(*imu.mag_heading_rad, maps::deg2rad(91.0), 1e-12);
  const TrackFix ok = parseTrackFixJson(json::parse("{" + base + R"(,"vehicle":42,"hpl_m":1.5,"vpl_m":2})"), "x");
  EXPECT_EQ(ok.flight, "42");
  EXPECT_DOUBLE_EQ(*ok.hpl_m, 1.5);
}

TEST(TrackFixJson, InsBlockGivesTheNominalInsPl) {
  // Consumer grade: λ = 9/12, P_nom = 0.5e-7 / 3: K = Q⁻¹(1.25e-8) = 5.5738 (normal table).
  const auto [h, v] = insNominalPl({2, 0.3, 0.4, 1.0});
  EXPECT_NEAR(h, 5.5738 * 0.5, 1e-3);
  EXPECT_NEAR(v, 5.5738 * 1.0, 1e-3);
}

}  // namespace
}  // namespace skylane::planner
