// `skylane track` end to end (issue 8): garbage and truncated input lose no good fix; a tracker
// killed mid-stream and restarted on its database loses no accepted fix; SIGTERM saves and
// exits; NMEA, UDP and RINEX replay inputs; bad approvals exit 2.
#include "maps/time.hpp"
#include "planner/tracking/track_store.hpp"
#include "tests/planner/track_events.hpp"
#include "tests/service/child_process.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

namespace skylane {
namespace {

using nlohmann::json;

using RunResult = test::CommandResult;

/// A bash script (written to a scratch file, so it may quote freely); its standard output.
RunResult sh(const std::string& script) {
  static int n = 0;
  const std::string file = test::scratchPath("script-" + std::to_string(++n) + ".sh");
  std::ofstream(file) << script << "\n";
  return test::runCommand("bash " + file);
}

const std::string kBin = SKYLANE_BINARY;
const std::string kExample = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve/mission.json";

std::vector<json> readEvents(const std::string& path) {
  std::vector<json> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) out.push_back(json::parse(line));
  }
  return out;
}

using test::ofType;

/// The bundled example approved once for the suite, and good fixes along its route (1 per s).
class TrackCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::scratchPath("track-cli"));
    std::filesystem::create_directories(*dir_);
    const RunResult r = sh(kBin + " approve " + kExample + " --out " + *dir_ + "/approve > /dev/null 2>&1");
    ASSERT_EQ(r.status, 0) << r.out;
    report_ = new json(json::parse(std::ifstream(*dir_ + "/approve/report.json")));
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete report_;
  }
  /// A fix k seconds after departure on the route (linear in lat/lon between route points).
  static json goodFix(int k) {
    const json& route = report_->at("route");
    const double t = k;
    std::size_t i = 1;
    while (i + 1 < route.size() && t > route[i].at("eta_s").get<double>()) ++i;
    const json& a = route[i - 1];
    const json& b = route[i];
    const double f = std::clamp((t - a.at("eta_s").get<double>()) / (b.at("eta_s").get<double>() - a.at("eta_s").get<double>()), 0.0, 1.0);
    auto mix = [&](const char* key) { return a.at(key).get<double>() + f * (b.at(key).get<double>() - a.at(key).get<double>()); };
    const std::string time = maps::formatRfc3339(maps::parseRfc3339("2020-01-01T14:00:00Z")->plus(k));
    return {{"flight", "zrh"}, {"time", time}, {"lat", mix("lat")}, {"lon", mix("lon")}, {"h_ell_m", mix("h_ell_m")},
            {"hpl_m", 0.5}, {"vpl_m", 0.5}};
  }
  static std::string approval() { return "zrh=" + *dir_ + "/approve/report.json"; }
  static std::string* dir_;
  static json* report_;
};
std::string* TrackCli::dir_ = nullptr;
json* TrackCli::report_ = nullptr;

TEST_F(TrackCli, NmeaWithoutADateNamesTheDateOptionAndEndsCleanly) {
  const std::string in = *dir_ + "/nodate.nmea";
  std::ofstream(in) << test::nmeaSentence("GPGGA,140000.00,4722.2795910,N,00831.9354490,E,4,12,0.8,468.8,M,47.35,M,,") << "\r\n"
                    << test::nmeaSentence("GPGST,140000.00,0.5,0.060,0.040,30.0,0.050,0.045,0.090") << "\r\n";
  const RunResult r = sh(kBin + " track --approval " + approval() + " --format nmea --input " + in + " --no-replan 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;  // a record that cannot be a fix is reported, not fatal
  EXPECT_NE(r.out.find("--date YYYY-MM-DD"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"line\":1"), std::string::npos) << r.out;
}

TEST_F(TrackCli, GarbageAndTruncatedLinesAreReportedAndEveryGoodFixIsChecked) {
  const std::string in = *dir_ + "/mixed.jsonl";
  std::ofstream f(in);
  std::set<int> bad_lines;
  int line = 0;
  for (int k = 0; k < 40; ++k) {
    f << goodFix(k).dump() << "\n";
    ++line;
    if (k % 5 == 2) {
      const std::string full = goodFix(100 + k).dump();
      f << full.substr(0, full.size() / 2) << "\n";  // truncated
      bad_lines.insert(++line);
    }
    if (k % 9 == 4) {
      f << "\x01\xff garbage \"{\n";
      bad_lines.insert(++line);
      f << "\n";  // an empty line is no record
      ++line;
    }
  }
  f.close();
  const RunResult r = sh(kBin + " track --approval " + approval() + " --input " + in + " --no-replan --map " + *dir_ +
                         "/mixed.svg > " + *dir_ + "/mixed_events.jsonl 2> " + *dir_ + "/mixed_err.txt");
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream svg(*dir_ + "/mixed.svg");
  const std::string map((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  for (const char* legend : {"approved route", "corridor (level 1)", "airspace (level 2)", "track: inside", "40 fixes"}) {
    EXPECT_NE(map.find(legend), std::string::npos) << legend;
  }
  const auto events = readEvents(*dir_ + "/mixed_events.jsonl");
  EXPECT_EQ(ofType(events, "fix").size(), 40u);
  std::set<int> rejected;
  for (const json& e : ofType(events, "rejected_input")) rejected.insert(e.at("line").get<int>());
  EXPECT_EQ(rejected, bad_lines);
  for (const json& e : ofType(events, "fix")) EXPECT_EQ(e.at("verdict"), "inside") << e.dump();
}

TEST_F(TrackCli, MavlinkTelemetryOverUdpFromAnIndependentVehicleIsTracked) {
  // GIVEN skylane tracking on a UDP port and a vehicle written on node-mavlink flying the approved
  // route for 30 s at 5 Hz (h_acc 150 mm, v_acc 200 mm), with junk bytes, a frame with a flipped
  // bit and a truncated copy of a frame among its datagrams
  const int port = 20000 + static_cast<int>(getpid() % 20000);
  char hex_port[8];
  std::snprintf(hex_port, sizeof hex_port, "%04X", port);
  const std::string events = *dir_ + "/mavlink_events.jsonl", err = *dir_ + "/mavlink_err.txt";
  const std::string report = *dir_ + "/approve/report.json";
  const std::string vehicle = std::string(SKYLANE_TEST_DATA) + "/../link/js/vehicle.mjs";
  const RunResult r = sh(kBin + " track --approval " + report + " --format mavlink --input udp://127.0.0.1:" + std::to_string(port) +
                         " --no-replan > " + events + " 2> " + err + " & pid=$!\n"
                         // WHEN the tracker listens (its port is in /proc/net/udp), the vehicle flies
                         "for i in $(seq 1 300); do grep -qi ':" + hex_port + " ' /proc/net/udp && break; sleep 0.1; done\n"
                         "node " + vehicle + " --report " + report + " --port " + std::to_string(port) + " --seconds 30 --garbage || echo vehicle-failed\n"
                         // and the tracker is stopped once it has written its fixes (or after a minute)
                         "for i in $(seq 1 600); do [ $(grep -c '\"event\":\"fix\"' " + events + ") -ge 150 ] && break; sleep 0.1; done\n"
                         "kill -TERM $pid; wait $pid; echo status=$?");
  ASSERT_EQ(r.out.find("vehicle-failed"), std::string::npos) << r.out;
  std::ifstream err_in(err);
  const std::string stderr_text((std::istreambuf_iterator<char>(err_in)), std::istreambuf_iterator<char>());
  ASSERT_NE(r.out.find("status=0"), std::string::npos) << r.out << stderr_text;
  // THEN every GPS_RAW_INT but the corrupted one is a fix inside the corridor, its PLs from the
  // accuracies by the documented rule (HPL = √(−2 ln 2e-9)·0.15 m, VPL = Q⁻¹(4.9e-8)·0.2 m)
  const auto all = readEvents(events);
  const auto fixes = ofType(all, "fix");
  EXPECT_EQ(fixes.size(), 150u);
  for (const json& f : fixes) {
    EXPECT_EQ(f.at("pl_source"), "mavlink_accuracy");
    EXPECT_EQ(f.at("verdict"), "inside") << f.dump();
    EXPECT_NEAR(f.at("hpl_m").get<double>(), std::sqrt(-2.0 * std::log(2e-9)) * 0.15, 2e-3);
    EXPECT_NEAR(f.at("vpl_m").get<double>(), 5.3314 * 0.2, 2e-3);
  }
  // AND the bad bytes are reported, not fatal
  const auto rejected = ofType(all, "rejected_input");
  ASSERT_GE(rejected.size(), 1u);
  bool bad_checksum = false;
  for (const json& e : rejected) bad_checksum = bad_checksum || e.at("error").get<std::string>().find("bad checksum") != std::string::npos;
  EXPECT_TRUE(bad_checksum) << rejected.front().dump();
}

/// `skylane track --format mavlink` on a free UDP port beside the node-mavlink vehicle flying
/// with `vehicle_args`; stopped once the vehicle has landed its flight. The events, and the
/// vehicle's own summary line.
struct MavlinkRun {
  std::vector<json> events;
  json vehicle;
  std::string out;
};

MavlinkRun flyMavlinkVehicle(const std::string& dir, const std::string& name, const std::string& vehicle_args,
                             const std::string& track_args = "") {
  static int n = 0;
  const int port = 20000 + static_cast<int>((getpid() * 7 + ++n) % 20000);
  char hex_port[8];
  std::snprintf(hex_port, sizeof hex_port, "%04X", port);
  const std::string events = dir + "/" + name + ".jsonl", vehicle_out = dir + "/" + name + "_vehicle.json";
  const std::string report = dir + "/approve/report.json";
  const std::string vehicle = std::string(SKYLANE_TEST_DATA) + "/../link/js/vehicle.mjs";
  MavlinkRun run;
  run.out = sh(kBin + " track --approval " + report + " --format mavlink --input udp://127.0.0.1:" + std::to_string(port) + " " +
               track_args + " > " + events +
               " 2> " + dir + "/" + name + "_err.txt & pid=$!\n"
               "for i in $(seq 1 300); do grep -qi ':" + hex_port + " ' /proc/net/udp && break; sleep 0.1; done\n"
               "node " + vehicle + " --report " + report + " --port " + std::to_string(port) + " " + vehicle_args + " > " + vehicle_out +
               " || echo vehicle-failed\n"
               "sleep 0.5; kill -TERM $pid; wait $pid; echo status=$?")
                .out;
  run.events = readEvents(events);
  std::ifstream v(vehicle_out);
  std::string line;
  if (std::getline(v, line) && !line.empty()) run.vehicle = json::parse(line);
  return run;
}

/// The handoff events' states of one mission type, in order.
std::vector<std::string> handoffStates(const std::vector<json>& events, const std::string& type) {
  std::vector<std::string> out;
  for (const json& e : ofType(events, "handoff")) {
    if (e.at("mission_type") == type) out.push_back(e.at("state"));
  }
  return out;
}

TEST_F(TrackCli, AReplanIsUploadedToTheVehicleWhichJoinsTheNewCorridorWithOneReplan) {
  // GIVEN a vehicle (node-mavlink) pushed 8 m aside by a 14 s gust, flying at 5 × real time for
  // 80 s. The upload's round trips run in wall time: under ASan the vehicle rejoined at fix 197
  // to 254, and a 70 s flight left 97–154 fixes after it, against the 100 asked below.
  const std::string plans = *dir_ + "/handoff_plans";
  const MavlinkRun r = flyMavlinkVehicle(*dir_, "handoff", "--seconds 80 --pace-ms 40 --gust-from 20 --gust-until 34 --gust-m 8",
                                         "--plans " + plans);
  ASSERT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  ASSERT_EQ(r.out.find("vehicle-failed"), std::string::npos) << r.out;
  // THEN one replan, its route and fence uploaded and acknowledged by the vehicle's autopilot
  const auto replans = ofType(r.events, "replan");
  ASSERT_EQ(replans.size(), 1u);
  EXPECT_EQ(replans[0].at("decision"), "approved");
  EXPECT_EQ(handoffStates(r.events, "mission"), (std::vector<std::string>{"sent", "acknowledged"}));
  EXPECT_EQ(handoffStates(r.events, "fence"), (std::vector<std::string>{"sent", "acknowledged"}));
  EXPECT_EQ(r.vehicle.at("missions"), 1);
  EXPECT_EQ(r.vehicle.at("fences"), 1);
  EXPECT_EQ(r.vehicle.at("route_changes"), 1);
  // AND the route the vehicle took is the one written as a plan (--plans): as many items
  std::ifstream plan_in(plans + "/Zurich_medical_supply_run__example_-route1.plan");
  ASSERT_TRUE(plan_in) << "no plan file in " << plans;
  const json plan = json::parse(plan_in);
  EXPECT_EQ(r.vehicle.at("items").at(0), plan.at("mission").at("items").size());
  // AND the vehicle, flying the uploaded route, is back inside: the last level-1 event is
  // `recovered`, and every fix after it is inside route 1's corridor
  std::size_t last_recovered = 0;
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const json& e = r.events[i];
    if ((e.at("event") == "recovered" || e.at("event") == "violation") && e.at("level") == "level1") last_recovered = i;
  }
  ASSERT_EQ(r.events[last_recovered].at("event"), "recovered") << r.events[last_recovered].dump();
  int after = 0;
  for (std::size_t i = last_recovered; i < r.events.size(); ++i) {
    if (r.events[i].at("event") != "fix") continue;
    EXPECT_EQ(r.events[i].at("levels").at("level1").at("verdict"), "inside") << r.events[i].dump();
    EXPECT_EQ(r.events[i].at("route_version"), 1);
    ++after;
  }
  EXPECT_GT(after, 100);
}

TEST_F(TrackCli, AVehicleThatRefusesTheUploadEndsTheHoldAndSaysWhy) {
  const MavlinkRun r = flyMavlinkVehicle(*dir_, "refused", "--seconds 50 --pace-ms 40 --gust-from 20 --gust-until 34 --gust-m 8 --refuse");
  ASSERT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  const auto states = handoffStates(r.events, "mission");
  ASSERT_GE(states.size(), 2u);
  EXPECT_EQ(states[0], "sent");
  EXPECT_EQ(states[1], "refused");
  for (const json& e : ofType(r.events, "handoff")) {
    EXPECT_NE(e.at("state"), "acknowledged") << e.dump();
    if (e.at("state") == "refused") {
      EXPECT_EQ(e.at("result"), "MAV_MISSION_DENIED");
    }
  }
  EXPECT_TRUE(handoffStates(r.events, "fence").empty());  // no fence for a route the vehicle refused
  EXPECT_EQ(r.vehicle.at("route_changes"), 0);
}

TEST_F(TrackCli, ALinkLostForTenSecondsDelaysTheUploadWhichIsSentAgainAndLosesNoFix) {
  // GIVEN the gust, and the link lost both ways for 10 s of flight (2 s of wall time) from the
  // moment the upload begins (its first MISSION_COUNT is lost)
  const MavlinkRun r = flyMavlinkVehicle(*dir_, "lost_link",
                                         "--seconds 60 --pace-ms 40 --gust-from 20 --gust-until 34 --gust-m 8 --silent-on-upload 10");
  ASSERT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  // THEN the upload is sent again until the vehicle hears it, and acknowledged
  EXPECT_EQ(handoffStates(r.events, "mission"), (std::vector<std::string>{"sent", "acknowledged"}));
  for (const json& e : ofType(r.events, "handoff")) {
    if (e.at("mission_type") == "mission" && e.at("state") == "acknowledged") {
      EXPECT_GE(e.at("resends").get<int>(), 1) << e.dump();
    }
  }
  EXPECT_EQ(ofType(r.events, "replan").size(), 1u);
  // AND every GPS fix the vehicle got through is tracked
  EXPECT_EQ(ofType(r.events, "fix").size(), r.vehicle.at("gps_sent").get<std::size_t>());
}

TEST_F(TrackCli, AUbxRecordingIsTrackedWithTheReceiversOwnProtectionLevels) {
  // GIVEN a recorded u-blox stream (frames built by gpsd's UBX module): a NAV-PVT with its NAV-PL
  const std::string ubx = *dir_ + "/receiver.ubx";
  const RunResult made = sh("/usr/bin/python3 " + std::string(SKYLANE_TEST_DATA) + "/../link/py/ubx_oracle.py encode | "
                            "python3 -c \"import sys, json; sys.stdout.buffer.write(b''.join(bytes.fromhex(json.loads(l)['hex']) "
                            "for l in list(sys.stdin)[:2]))\" > " + ubx);
  ASSERT_EQ(made.status, 0) << made.out;
  // WHEN skylane tracks it
  const RunResult r = sh(kBin + " track --approval " + *dir_ + "/approve/report.json --format ubx --input " + ubx + " --no-replan");
  ASSERT_EQ(r.status, 0) << r.out;
  // THEN one fix, its PLs the receiver's (frame 3, TMIR 1e-5 %) converted to the mission's risk
  std::vector<json> events;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '{') events.push_back(json::parse(line));
  }
  const auto fixes = ofType(events, "fix");
  ASSERT_EQ(fixes.size(), 1u) << r.out;
  EXPECT_EQ(fixes[0].at("pl_source"), "ubx_pl");
  EXPECT_NEAR(fixes[0].at("hpl_m").get<double>(), 2.495, 2e-3);
}

TEST_F(TrackCli, MavlinkTelemetryOnASerialLineIsTracked) {
  // GIVEN node-mavlink's GPS_RAW_INT frames along the route (the vehicle, recorded to a file)
  const std::string recorded = *dir_ + "/serial.bin";
  const std::string vehicle_frames = *dir_ + "/serial_frames.hex";
  const RunResult made = sh("node " + std::string(SKYLANE_TEST_DATA) + "/../link/js/vehicle.mjs --report " + *dir_ +
                            "/approve/report.json --port 9 --seconds 10 --pace-ms 0 --record " + recorded);
  ASSERT_EQ(made.status, 0) << made.out;
  // WHEN they arrive on a serial line (a pseudo-terminal) that skylane reads in raw mode at 115200 Bd
  const std::string events = *dir_ + "/serial_events.jsonl";
  const RunResult r = sh("exec 3< <(/usr/bin/python3 " + std::string(SKYLANE_TEST_DATA) + "/../link/py/pty_serial.py " + recorded +
                         " 3)\nread -r tty <&3\n" + kBin + " track --approval " + *dir_ + "/approve/report.json --format mavlink --input $tty --baud 115200 "
                         "--no-handoff > " + events + " 2>/dev/null & pid=$!\n"
                         "for i in $(seq 1 300); do [ $(grep -c '\"event\":\"fix\"' " + events + ") -ge 51 ] && break; sleep 0.1; done\n"
                         "kill -TERM $pid; wait $pid; echo status=$?");
  ASSERT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  // THEN every GPS_RAW_INT (10 s at 5 Hz) is a fix inside the corridor
  const auto fixes = ofType(readEvents(events), "fix");
  EXPECT_EQ(fixes.size(), 51u);
  for (const json& f : fixes) EXPECT_EQ(f.at("verdict"), "inside") << f.dump();
}

/// Runs `command` in the background and kills it with SIGKILL (no chance to save) once its
/// database (with its write-ahead log) has grown past 256 KiB — some hundreds of fixes stored,
/// however slow the build (a sanitizer's) — or after two minutes.
RunResult killOnceStoring(const std::string& command, const std::string& db) {
  return sh(command + " > /dev/null 2>&1 & pid=$!; for i in $(seq 1 1200); do "
                      "s=$(cat '" + db + "' '" + db + "-wal' 2>/dev/null | wc -c); [ \"$s\" -gt 262144 ] && break; "
                      "kill -0 $pid 2>/dev/null || break; sleep 0.1; done; kill -9 $pid 2>/dev/null; wait $pid; echo status=$?");
}

TEST_F(TrackCli, KilledAndRestartedTrackerLosesNoAcceptedFix) {
  // GIVEN a long file of good fixes (a few seconds of work with the database)
  constexpr int kFixes = 60000;
  const std::string db = *dir_ + "/track.sqlite", all = *dir_ + "/all.jsonl";
  std::filesystem::remove(db);
  {
    std::ofstream f(all);
    for (int k = 0; k < kFixes; ++k) f << goodFix(k).dump() << "\n";
  }
  const std::string cmd = kBin + " track --approval " + approval() + " --input " + all + " --db " + db + " --batch 50 --no-replan";
  // WHEN the tracker is killed mid-stream and restarted with the same database and input
  const RunResult first = killOnceStoring(cmd, db);
  ASSERT_NE(first.out.find("status=137"), std::string::npos) << "the first run ended before the kill: " << first.out;
  // (the report file is moved away: the restarted tracker takes the approval from its database)
  const std::string report = *dir_ + "/approve/report.json";
  std::filesystem::rename(report, report + ".away");
  const RunResult second = sh(cmd + " 2>&1 > /dev/null");
  std::filesystem::rename(report + ".away", report);
  ASSERT_EQ(second.status, 0) << second.out;
  EXPECT_NE(second.out.find("resumed flight zrh"), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("resuming after line"), std::string::npos) << second.out;
  // THEN the database holds every accepted fix exactly once, and nothing was rejected
  std::vector<int> count(kFixes + 1, 0);
  for (const json& e : planner::TrackStore(db).events("fix")) ++count[static_cast<std::size_t>(e.at("line").get<int>())];
  int missing = 0, twice = 0;
  for (int k = 1; k <= kFixes; ++k) {
    missing += count[static_cast<std::size_t>(k)] == 0;
    twice += count[static_cast<std::size_t>(k)] > 1;
  }
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(twice, 0);
  EXPECT_TRUE(planner::TrackStore(db).events("rejected_input").empty());
}

TEST_F(TrackCli, KilledTwiceTheOutFileHoldsEveryEventOnceAsTheDatabaseDoes) {
  // GIVEN a long file of good fixes, the tracker writing its events to --out and its database
  constexpr int kFixes = 60000;
  const std::string db = *dir_ + "/out_kill.sqlite", all = *dir_ + "/out_kill_fixes.jsonl", out = *dir_ + "/out_kill.jsonl";
  std::filesystem::remove(db);
  std::filesystem::remove(out);
  {
    std::ofstream f(all);
    for (int k = 0; k < kFixes; ++k) f << goodFix(k).dump() << "\n";
  }
  const std::string cmd =
      kBin + " track --approval " + approval() + " --input " + all + " --db " + db + " --out " + out + " --batch 50 --no-replan";
  // WHEN it is killed (SIGKILL) twice mid-stream and run to the end
  ASSERT_NE(killOnceStoring(cmd, db).out.find("status=137"), std::string::npos);
  // (the second kill, half a second into the resumed run, may find it done: then it is a restart)
  sh(cmd + " > /dev/null 2>&1 & pid=$!; sleep 0.5; kill -9 $pid 2>/dev/null; wait $pid");
  const RunResult last = sh(cmd + " 2>&1; echo status=$?");
  ASSERT_NE(last.out.find("status=0"), std::string::npos) << last.out;
  // THEN every line of the file is whole JSON, and its events are the database's, in order, once
  std::vector<std::string> file_lines;
  {
    std::ifstream in(out);
    std::string line;
    while (std::getline(in, line)) file_lines.push_back(line);
  }
  std::vector<std::string> stored;
  for (const json& e : planner::TrackStore(db).events()) stored.push_back(e.dump());
  std::vector<std::string> written;
  for (const std::string& l : file_lines) {
    json e;
    ASSERT_NO_THROW(e = json::parse(l)) << "a torn line: " << l;
    written.push_back(e.dump());
  }
  EXPECT_EQ(written.size(), stored.size());
  EXPECT_TRUE(written == stored);
  EXPECT_EQ(ofType(readEvents(out), "fix").size(), static_cast<std::size_t>(kFixes));
}

TEST_F(TrackCli, KilledNmeaTrackerRestartedWithoutAnIdLosesNoEpoch) {
  // GIVEN 150 NMEA epochs (RMC, GGA, GST) along the route through a FIFO, the approval given
  // without an ID (the flight takes the mission's name)
  constexpr int kEpochs = 40000;
  const std::string db = *dir_ + "/nmea.sqlite", all = *dir_ + "/all.nmea";
  std::filesystem::remove(db);
  int lines = 0;
  {
    std::ofstream f(all);
    for (int k = 0; k < kEpochs; ++k) {
      const json fix = goodFix(k);
      const maps::CalendarTime c = maps::utcFromGps(maps::parseRfc3339("2020-01-01T14:00:00Z")->plus(k));
      char hms[16];
      std::snprintf(hms, sizeof hms, "%02d%02d%02d.00", c.hour, c.minute, static_cast<int>(c.second));
      char date[8];
      std::snprintf(date, sizeof date, "%02d%02d%02d", c.day, c.month, c.year % 100);
      const std::string lat = test::nmeaAngle(fix.at("lat").get<double>(), true);
      const std::string lon = test::nmeaAngle(fix.at("lon").get<double>(), false);
      char alt[64];
      std::snprintf(alt, sizeof alt, ",4,12,0.8,%.3f,M,47.35,M,,", fix.at("h_ell_m").get<double>() - 47.35);
      f << test::nmeaSentence(std::string("GPRMC,") + hms + ",A," + lat + "," + lon + ",0.0,0.0," + date + ",,,D") << "\r\n";
      f << test::nmeaSentence(std::string("GPGGA,") + hms + "," + lat + "," + lon + alt) << "\r\n";
      f << test::nmeaSentence(std::string("GPGST,") + hms + ",0.5,0.060,0.040,30.0,0.050,0.045,0.090") << "\r\n";
      lines += 3;
    }
  }
  const std::string report = *dir_ + "/approve/report.json";
  // WHEN the tracker is killed mid-stream and restarted on the same database and file
  const std::string cmd = kBin + " track --approval " + report + " --format nmea --input " + all + " --db " + db +
                          " --batch 9 --no-replan";
  const RunResult first = killOnceStoring(cmd, db);
  ASSERT_NE(first.out.find("status=137"), std::string::npos) << "the first run ended before the kill: " << first.out;
  const RunResult second = sh(cmd + " 2>&1 > /dev/null");
  ASSERT_EQ(second.status, 0) << second.out;
  EXPECT_NE(second.out.find("resumed flight"), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("resuming after line"), std::string::npos) << second.out;
  // THEN every epoch is in the database once (its GGA line), and none was rejected
  std::vector<int> count(static_cast<std::size_t>(lines) + 1, 0);
  for (const json& e : planner::TrackStore(db).events("fix")) ++count[static_cast<std::size_t>(e.at("line").get<int>())];
  int missing = 0, twice = 0;
  for (int k = 0; k < kEpochs; ++k) {
    missing += count[static_cast<std::size_t>(3 * k + 2)] == 0;
    twice += count[static_cast<std::size_t>(3 * k + 2)] > 1;
  }
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(twice, 0);
  EXPECT_TRUE(planner::TrackStore(db).events("rejected_input").empty());
}

TEST_F(TrackCli, SigtermSavesTheStateAndExitsCleanly) {
  const std::string fifo = *dir_ + "/term.fifo", db = *dir_ + "/term.sqlite", all = *dir_ + "/term.jsonl";
  std::filesystem::remove(db);
  std::filesystem::remove(fifo);
  {
    std::ofstream f(all);
    for (int k = 0; k < 30; ++k) f << goodFix(k).dump() << "\n";
  }
  const RunResult r = sh("mkfifo " + fifo + "; (cat " + all + "; sleep 5) > " + fifo + " & " + kBin + " track --approval " +
                         approval() + " --input " + fifo + " --db " + db + " --no-replan > " + *dir_ +
                         "/term_events.jsonl 2> " + *dir_ + "/term_err.txt & pid=$!; " +
                         // the signal once the 30 fixes are out (the quiet FIFO flushes them), however slow the build
                         "for i in $(seq 600); do [ \"$(grep -c '\"event\":\"fix\"' " + *dir_ +
                         "/term_events.jsonl)\" -ge 30 ] && break; sleep 0.1; done; kill -TERM $pid; wait $pid; echo status=$?");
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  EXPECT_EQ(ofType(readEvents(*dir_ + "/term_events.jsonl"), "fix").size(), 30u);
  std::ifstream err(*dir_ + "/term_err.txt");
  const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("stopped by a signal; state saved"), std::string::npos) << text;
  EXPECT_EQ(planner::TrackStore(db).events("fix").size(), 30u);
}

TEST_F(TrackCli, AClosedOutputPipeStopsCleanlyAndARestartLosesNoFix) {
  const std::string db = *dir_ + "/pipe.sqlite", all = *dir_ + "/pipe.jsonl", err = *dir_ + "/pipe_err.txt";
  std::filesystem::remove(db);
  {
    std::ofstream f(all);
    for (int k = 0; k < 3000; ++k) f << goodFix(k % 150).dump() << "\n";  // (times repeat: rejected, also events)
  }
  // GIVEN a reader that goes away after one line
  const std::string cmd = kBin + " track --approval " + approval() + " --input " + all + " --db " + db + " --no-replan";
  const RunResult r = sh(cmd + " 2> " + err + " | head -n 1 > /dev/null; echo status=${PIPESTATUS[0]}");
  // THEN the tracker is not killed by SIGPIPE: it saves and exits 0, saying why
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  std::ifstream in(err);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("the output was closed; state saved"), std::string::npos) << text;
  const std::size_t first = planner::TrackStore(db).events("fix").size();
  EXPECT_GT(first, 0u);
  // AND a restart on the same database reads on: every accepted fix is in it exactly once
  const RunResult again = sh(cmd + " > /dev/null 2>&1; echo status=$?");
  EXPECT_NE(again.out.find("status=0"), std::string::npos) << again.out;
  EXPECT_EQ(planner::TrackStore(db).events("fix").size(), 150u);
  EXPECT_EQ(planner::TrackStore(db).events("rejected_input").size(), 2850u);
}

/// Shell that waits (up to 20 s) until a process listens on the UDP port: a loaded machine can
/// take longer than any fixed sleep to start the tracker, and datagrams sent before are lost.
std::string waitForUdpPort(int port) {
  char hex[8];
  std::snprintf(hex, sizeof hex, "%04X", port);
  return std::string("for i in $(seq 400); do grep -qi ':") + hex + " ' /proc/net/udp && break; sleep 0.05; done; ";
}

TEST_F(TrackCli, UdpInputAndAStaleFlightOnAQuietLink) {
  const std::string events = *dir_ + "/udp_events.jsonl";
  std::string send;
  const int port = test::freeUdpPort();
  const std::string udp = "127.0.0.1/" + std::to_string(port);
  for (int k = 0; k < 5; ++k) send += "echo \x27" + goodFix(k).dump() + "\x27 > /dev/udp/" + udp + "; sleep 0.05; ";
  const RunResult r = sh(kBin + " track --approval " + approval() + " --input udp://127.0.0.1:" + std::to_string(port) +
                         " --stale-after 1 --no-replan > " + events + " 2>/dev/null & pid=$!; " + waitForUdpPort(port) + send +
                         " sleep 2.5; kill -TERM $pid; wait $pid; echo status=$?");
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  const auto ev = readEvents(events);
  EXPECT_EQ(ofType(ev, "fix").size(), 5u);
  ASSERT_EQ(ofType(ev, "stale").size(), 1u);
  EXPECT_EQ(ofType(ev, "stale")[0].at("last_fix"), "2020-01-01T14:00:04.000Z");
}

/// Sends each line as one datagram to 127.0.0.1:port as fast as the socket takes them.
void floodUdp(int port, const std::vector<std::string>& lines) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (const std::string& l : lines) sendto(fd, l.data(), l.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  close(fd);
}

/// `skylane track` on a UDP port, run in the background until the returned stop() (SIGTERM).
struct BackgroundTrack {
  std::string pid_file;
  std::thread runner;
  RunResult result;
  BackgroundTrack(const std::string& command, const std::string& pid_file_path, int port) : pid_file(pid_file_path) {
    std::filesystem::remove(pid_file);
    runner = std::thread([this, command] { result = sh(command + " & echo $! > " + pid_file + "; wait $!; echo status=$?"); });
    (void)sh(waitForUdpPort(port));
  }
  RunResult stop() {
    const RunResult r = sh("kill -TERM $(cat " + pid_file + ")");
    runner.join();
    return result;
  }
};

TEST_F(TrackCli, UdpFloodIntoASmallBufferReportsEveryDroppedDatagram) {
  // GIVEN the tracker on a UDP port with a small receive buffer
  const int port = 47833;
  const std::string events = *dir_ + "/flood_events.jsonl", err = *dir_ + "/flood_err.txt";
  BackgroundTrack track(kBin + " track --approval " + approval() + " --input udp://127.0.0.1:" + std::to_string(port) +
                            " --udp-buffer 4096 --no-replan --max-time-jump 86400 > " + events + " 2> " + err,
                        *dir_ + "/flood.pid", port);
  // WHEN 5,000 fixes come flat out, one datagram each
  constexpr int kSent = 5000;
  std::vector<std::string> lines;
  for (int k = 0; k < kSent; ++k) lines.push_back(goodFix(k).dump() + "\n");
  floodUdp(port, lines);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the queue drains, the input goes quiet
  const RunResult r = track.stop();
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out << test::readFile(err);
  // THEN the drops are events, and every datagram sent is accepted, rejected or counted dropped
  const auto ev = readEvents(events);
  std::uint64_t dropped = 0, last_total = 0;
  for (const json& e : ofType(ev, "input_dropped")) {
    EXPECT_EQ(e.at("source"), "udp://127.0.0.1:" + std::to_string(port));
    dropped += e.at("count").get<std::uint64_t>();
    EXPECT_EQ(e.at("total").get<std::uint64_t>(), dropped);  // running total
    last_total = e.at("total").get<std::uint64_t>();
  }
  const std::size_t accepted = ofType(ev, "fix").size(), rejected = ofType(ev, "rejected_input").size();
  EXPECT_GT(dropped, 0u);
  EXPECT_EQ(accepted + rejected + dropped, static_cast<std::size_t>(kSent))
      << accepted << " accepted, " << rejected << " rejected, " << dropped << " dropped";
  // AND the summary says so
  const std::string summary = std::to_string(accepted) + " fixes accepted, " + std::to_string(rejected) + " rejected, " +
                              std::to_string(last_total) + " datagrams dropped by the kernel";
  EXPECT_NE(test::readFile(err).find(summary), std::string::npos) << test::readFile(err);
  std::printf("UDP flood: %d sent, %zu accepted, %zu rejected, %llu dropped by the kernel\n", kSent, accepted, rejected,
              static_cast<unsigned long long>(dropped));
}

TEST_F(TrackCli, UdpAtAModestRateIntoABigBufferDropsNothing) {
  const int port = 47834;
  const std::string events = *dir_ + "/modest_events.jsonl", err = *dir_ + "/modest_err.txt";
  BackgroundTrack track(kBin + " track --approval " + approval() + " --input udp://127.0.0.1:" + std::to_string(port) +
                            " --udp-buffer 4194304 --no-replan > " + events + " 2> " + err,
                        *dir_ + "/modest.pid", port);
  constexpr int kSent = 1000;
  for (int k = 0; k < kSent; k += 50) {  // 50 fixes every 10 ms: 5,000 a second
    std::vector<std::string> lines;
    for (int j = k; j < k + 50; ++j) lines.push_back(goodFix(j).dump() + "\n");
    floodUdp(port, lines);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const RunResult r = track.stop();
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out << test::readFile(err);
  const auto ev = readEvents(events);
  EXPECT_EQ(ofType(ev, "input_dropped").size(), 0u);
  EXPECT_EQ(ofType(ev, "fix").size(), static_cast<std::size_t>(kSent));
  EXPECT_NE(test::readFile(err).find("0 datagrams dropped by the kernel"), std::string::npos) << test::readFile(err);
}

TEST_F(TrackCli, BadApprovalsExitTwoNamingTheField) {
  const std::string bad = *dir_ + "/bad_report.json";
  json j = *report_;
  j.erase("route");
  std::ofstream(bad) << j.dump();
  const RunResult r = sh(kBin + " track --approval " + bad + " --input /dev/null 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("$.route"), std::string::npos) << r.out;
  // A mission changed since its approval is refused (the report keeps its SHA-256).
  json changed = *report_;
  for (json& in : changed.at("inputs")) {
    if (in.at("role") == "mission") in["sha256"] = std::string(64, '0');
  }
  std::ofstream(*dir_ + "/changed_report.json") << changed.dump();
  const RunResult c = sh(kBin + " track --approval " + *dir_ + "/changed_report.json --input /dev/null 2>&1");
  EXPECT_EQ(c.status, 2) << c.out;
  EXPECT_NE(c.out.find("the mission changed since it was approved"), std::string::npos) << c.out;
  const RunResult fmt = sh(kBin + " track --approval " + approval() + " --input /dev/null --level1 5/3 2>&1");
  EXPECT_EQ(fmt.status, 2) << fmt.out;
  EXPECT_NE(fmt.out.find("--level1"), std::string::npos) << fmt.out;
}

TEST_F(TrackCli, FlyWritesFixesThatTrackReadsAndBadOptionsExitTwo) {
  const std::string report = *dir_ + "/approve/report.json", fixes = *dir_ + "/fly.jsonl", faults = *dir_ + "/fly_faults.json";
  // GIVEN the approved example flown by the simulator with a tactical IMU and a 60 m step on one satellite
  std::ofstream(faults) << R"({"faults": [{"type": "satellite", "sats": ["G20"], "start_s": 20, "end_s": 40, "bias_m": 60}]})";
  const RunResult fly = sh(kBin + " fly " + report + " --out " + fixes + " --imu tactical --faults " + faults +
                           " --flight zrh --truth " + *dir_ + "/fly_truth.csv 2>&1; echo status=$?");
  ASSERT_NE(fly.out.find("status=0"), std::string::npos) << fly.out;
  // WHEN skylane track reads them
  const RunResult track = sh(kBin + " track --approval " + approval() + " --input " + fixes + " --no-replan --map " + *dir_ +
                             "/fly.svg > " + *dir_ + "/fly_events.jsonl 2>/dev/null; echo status=$?");
  ASSERT_NE(track.out.find("status=0"), std::string::npos) << track.out;
  std::ifstream svg(*dir_ + "/fly.svg");
  const std::string map((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(map.find("excluded G20"), std::string::npos);  // the map marks the exclusion
  // THEN every fix is accepted, from the first aligned on the fault-mode GNSS/INS flow
  const auto ev = readEvents(*dir_ + "/fly_events.jsonl");
  const auto fx = ofType(ev, "fix");
  EXPECT_TRUE(ofType(ev, "rejected_input").empty());
  std::ifstream truth(*dir_ + "/fly_truth.csv");
  const auto rows = std::count(std::istreambuf_iterator<char>(truth), std::istreambuf_iterator<char>(), '\n');
  EXPECT_EQ(static_cast<long>(fx.size()), rows - 1);
  ASSERT_GT(fx.size(), 100u);
  int ins = 0, excluded = 0;
  for (const json& f : fx) {
    ins += f.at("pl_source") == "gnss_ins";
    if (f.contains("excluded") && f.at("excluded").size() == 1 && f.at("excluded")[0] == "G20") ++excluded;
  }
  EXPECT_EQ(ins, static_cast<int>(fx.size()) - 1);
  EXPECT_EQ(excluded, 20);
  // AND bad options name what was expected and exit 2
  RunResult bad = sh(kBin + " fly " + report + " --out " + fixes + " --imu toy 2>&1; echo status=$?");
  EXPECT_NE(bad.out.find("aviation, tactical or consumer"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("status=2"), std::string::npos) << bad.out;
  std::ofstream(faults) << R"([{"type": "satellite", "sats": ["G20"], "start_s": 20, "end_s": 10, "bias_m": 60}])";
  bad = sh(kBin + " fly " + report + " --out " + fixes + " --faults " + faults + " 2>&1; echo status=$?");
  EXPECT_NE(bad.out.find("[0].end_s"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("status=2"), std::string::npos) << bad.out;
}

TEST(TrackCliRinex, ObservationReplayGivesSkylanesOwnPls) {
  // GIVEN a flight approved from GSI station 3040 (Japan) 1 km east, with the station's own
  // broadcast ephemerides as orbits, departing at the first observation
  const std::string dir = test::scratchPath("track-rinex");
  std::filesystem::create_directories(dir);
  const std::string data = SKYLANE_TEST_DATA;
  const json mission{{"name", "GSI 3040 hop"},
                     {"vehicle", {{"lateral_m", 20.0}, {"longitudinal_m", 25.0}, {"height_m", 2.0}, {"cruise_speed_mps", 12}}},
                     {"k1", 1.2},
                     {"k2", 100},
                     {"start", {{"lat", 35.132066}, {"lon", 139.624302}}},
                     {"goal", {{"lat", 35.132066}, {"lon", 139.635}}},
                     {"altitude", {{"cruise_agl_m", 40}, {"min_agl_m", 20}, {"max_agl_m", 120}}},
                     {"departure", "2005-04-02T00:00:00Z"},
                     {"ground_amsl_m", 39.0},
                     {"orbits", {data + "/gnss/30400920.05n"}},
                     {"integrity", {{"method", "raim"}, {"mask_deg", 10}}},
                     {"planner", {{"iterations", 300}, {"seed", 3}}}};
  std::ofstream(dir + "/mission.json") << mission.dump(1);
  const RunResult a = sh(kBin + " approve " + dir + "/mission.json --out " + dir + "/approve > /dev/null 2>&1");
  ASSERT_EQ(a.status, 0) << a.out;
  // WHEN the station's observations are replayed
  const RunResult r = sh(kBin + " track --approval " + dir + "/approve/report.json --format rinex --input " + data +
                         "/gnss/30400920.05o --nav " + data + "/gnss/30400920.05n --no-replan > " + dir + "/events.jsonl 2>/dev/null");
  ASSERT_EQ(r.status, 0) << r.out;
  // THEN every epoch of the hour (30 s) is a fix with skylane's PLs; where the geometry is
  // good the volume lies in the airspace box, and a VPL of kilometres leaves it
  const auto fixes = ofType(readEvents(dir + "/events.jsonl"), "fix");
  EXPECT_EQ(fixes.size(), 120u);
  int inside2 = 0;
  for (const json& f : fixes) {
    EXPECT_EQ(f.at("pl_source"), "raw");
    EXPECT_GT(f.at("hpl_m").get<double>(), 1.0);
    const bool in2 = f.at("levels").at("level2").at("verdict") == "inside";
    if (f.at("vpl_m").get<double>() < 100.0) {
      EXPECT_TRUE(in2) << f.dump();
    }
    if (f.at("vpl_m").get<double>() > 2600.0) {
      EXPECT_FALSE(in2) << f.dump();  // VAL₂ = 2500 m
    }
    inside2 += in2;
  }
  EXPECT_GT(inside2, 100);
}

}  // namespace
}  // namespace skylane
