// skylane on NATS JetStream against a real nats-server (started by the test on a loopback port
// with a file store): approvals through the work queue, tracking through partitioned fix
// streams with the events of `skylane track` on the same approval and fixes, a track worker
// killed with kill -9 and replaced, the server killed and restarted on its store, duplicates,
// out-of-order fixes and bad messages.

#include "maps/time.hpp"
#include "service/approval_bundle.hpp"
#include "service/nats_client.hpp"
#include "service/nats_layout.hpp"
#include "tests/service/child_process.hpp"
#include "tests/service/route_fix.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <csignal>
#include <cmath>
#include <atomic>
#include <map>
#include <set>
#include <thread>

namespace skylane {
namespace {

using nlohmann::json;
using service::NatsClient;
using test::ChildProcess;
using test::NatsServer;
namespace nats = service::nats;

constexpr int kPartitions = 4;

/// The example zones put as authority.zurich, the example mission made from it approved as a1
/// (its report), two track workers, and four flights of it started.
struct ZurichFlights {
  std::uint64_t v1 = 0;
  json rep;
  std::unique_ptr<ChildProcess> w1, w2;
  std::vector<std::string> flights = {"f1", "f2", "f3", "f4"};
};

// NatsError is thrown inside libskylane_nats.so and caught by type outside it; no server needed.
TEST(NatsClient, ARefusedConnectionIsANatsErrorNamingTheUrl) {
  // GIVEN a loopback port nothing listens on
  const std::string url = "nats://127.0.0.1:" + std::to_string(test::freeTcpPort());
  // WHEN a client connects THEN the module's NatsError reaches the caller as that type
  try {
    NatsClient client(url, "test", std::chrono::milliseconds(500));
    FAIL() << "connected to " << url;
  } catch (const service::NatsError& e) {
    EXPECT_NE(std::string(e.what()).find("connecting to " + url), std::string::npos) << e.what();
  }
}

class NatsWorkers : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!NatsServer::installed()) GTEST_SKIP() << "nats-server is not installed (scripts/setup.sh installs it)";
    dir_ = test::scratchPath("nats-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    server_ = std::make_unique<NatsServer>(std::filesystem::path(dir_) / "server", kPartitions);
    const test::CommandResult setup = test::runCommand(std::string(SKYLANE_BINARY) + " nats setup --nats " + server_->url() +
                                                       " --partitions " + std::to_string(kPartitions));
    ASSERT_EQ(setup.status, 0) << setup.out;
    client_ = std::make_unique<NatsClient>(server_->url(), "test");
  }
  std::unique_ptr<ChildProcess> worker(const std::string& role, const std::string& name, const std::string& partitions = "all") {
    return std::make_unique<ChildProcess>(
        std::vector<std::string>{SKYLANE_BINARY, "worker", "--nats", server_->url(), "--role", role, "--name", name, "--partitions",
                                 partitions, "--cache", dir_ + "/cache-" + name, "--work", dir_ + "/work-" + name},
        dir_ + "/" + name + ".log");
  }
  /// Requests the example mission's approval as acme/`id` and waits for its status.
  json approve(const std::string& id, const std::string& mission = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json") {
    const test::CommandResult r = test::runCommand(std::string(SKYLANE_BINARY) + " nats approve " + mission + " --nats " + server_->url() +
                                                   " --operator acme --id " + id + " --wait 300 2>&1");
    return r.out.empty() || r.out[0] != '{' ? json{{"status", "no outcome: " + r.out}} : json::parse(r.out);
  }
  /// The approved report (from the approval's bundle in the bucket).
  json report(const std::string& id) {
    const auto b = client_->get(nats::kApprovalBucket, "acme." + id + ".bundle");
    return b ? json::parse(service::parseBundle(b->value, "bundle").report) : json();
  }
  static json fixAt(const json& rep, int k, double off_m = 0.0, double pl_m = 0.5) { return test::fixAlongRoute(rep, k, off_m, pl_m); }
  /// Every event in the stream, each with its subject.
  std::vector<json> events() {
    std::vector<json> out;
    const std::uint64_t last = client_->lastSequence(nats::kEventStream);
    for (std::uint64_t s = 1; s <= last; ++s) {
      if (auto m = client_->message(nats::kEventStream, s)) {
        json e = json::parse(m->data);
        e["_subject"] = m->subject;
        out.push_back(e);
      }
    }
    return out;
  }
  /// Waits until `done(events)` holds (at most `seconds`); the events.
  std::vector<json> waitFor(const std::function<bool(const std::vector<json>&)>& done, int seconds = 60) {
    std::vector<json> ev;
    for (int i = 0; i < seconds * 10; ++i) {
      ev = events();
      if (done(ev)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return ev;
  }
  static std::size_t count(const std::vector<json>& ev, const std::string& type, const std::string& flight = {}) {
    return static_cast<std::size_t>(std::count_if(ev.begin(), ev.end(), [&](const json& e) {
      return e.at("event") == type && (flight.empty() || e.value("flight", "") == flight);
    }));
  }
  /// The events of `skylane track` on the approval and the fixes (lines as published).
  std::vector<json> trackEvents(const std::string& id, const std::string& flight, const std::vector<std::string>& lines) {
    const std::string rep = dir_ + "/" + id + "-report.json", fixes = dir_ + "/" + flight + "-fixes.jsonl";
    std::ofstream(rep) << report(id).dump();
    {
      std::ofstream f(fixes);
      for (const std::string& l : lines) f << l << "\n";
    }
    // The report's mission, from the approve worker's folder (its sha256 is checked).
    const test::CommandResult cli = test::runCommand(std::string(SKYLANE_BINARY) + " track --approval " + flight + "=" + rep + " --input " +
                                                     fixes + " 2>&1");
    std::vector<json> out;
    std::istringstream in(cli.out);
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line[0] == '{') out.push_back(json::parse(line));
    }
    EXPECT_FALSE(out.empty()) << cli.out;
    return out;
  }
  /// An event without what names the input (subject, sequence, line, file) and wall-clock times.
  static json comparable(json e) {
    for (const char* k : {"line", "source", "report", "error", "planning_time_s", "operator", "input_seq", "subject", "_subject"}) e.erase(k);
    if (e.at("event") == "rejected_input") e.erase("flight");
    return e;
  }
  /// See ZurichFlights; its report is null when the approval failed.
  ZurichFlights startZurichFlights(bool second_worker = true);
  std::string dir_;
  std::unique_ptr<NatsServer> server_;
  std::unique_ptr<NatsClient> client_;
};

TEST_F(NatsWorkers, AFlightsEventsEqualSkylaneTracksAndBadMessagesAreRejectedByName) {
  auto approver = worker("approve", "ap1");
  ASSERT_EQ(approve("a1").at("status"), "approved") << approver->log();
  auto tracker = worker("track", "tr1");
  const json rep = report("a1");
  // On the route, then 40 m off it (a level-1 violation by position: a replan), then a bad line.
  std::vector<std::string> lines;
  for (int k = 0; k < 30; ++k) lines.push_back(fixAt(rep, k, k >= 12 && k < 20 ? 40.0 : 0.0).dump());
  lines.push_back("{\"time\": 3}");
  const std::string subject = nats::fixSubject("acme", "f1");
  client_->publish(subject, json{{"start", {{"approval", "a1"}}}}.dump());
  for (const std::string& l : lines) client_->publish(subject, l);
  // Bad messages elsewhere: not JSON, a flight never started, a subject with no valid flight id.
  client_->publish(nats::fixSubject("acme", "f2"), "not json at all");
  client_->publish(nats::fixSubject("acme", "f3"), lines[0]);
  client_->publish("skylane.fix.acme._bad", lines[0]);
  const std::vector<json> ev = waitFor([](const std::vector<json>& e) { return count(e, "rejected_input") >= 4 && count(e, "fix") >= 30; });
  ASSERT_EQ(count(ev, "fix", "f1"), 30u) << tracker->log();
  std::vector<json> mine;
  for (const json& e : ev) {
    if (e.at("_subject") == nats::eventSubject("acme", "f1") && e.at("event") != "flight_started") mine.push_back(comparable(e));
  }
  std::vector<json> expected;
  for (const json& e : trackEvents("a1", "f1", lines)) expected.push_back(comparable(e));
  ASSERT_EQ(mine.size(), expected.size());
  for (std::size_t i = 0; i < mine.size(); ++i) EXPECT_EQ(mine[i], expected[i]) << i;
  EXPECT_GE(count(ev, "replan", "f1"), 1u);
  // Each bad message: a rejected_input event naming the subject it was published to and why.
  std::map<std::string, std::string> why;
  for (const json& e : ev) {
    if (e.at("event") == "rejected_input") why[e.at("subject")] = e.at("error");
  }
  EXPECT_NE(why[nats::fixSubject("acme", "f2")].find("syntax"), std::string::npos) << why[nats::fixSubject("acme", "f2")];
  EXPECT_NE(why[nats::fixSubject("acme", "f3")].find("not started"), std::string::npos);
  EXPECT_NE(why["skylane.fix.acme._bad"].find("names no operator and flight"), std::string::npos);
  EXPECT_NE(why[subject].find("$.time"), std::string::npos);
  EXPECT_TRUE(tracker->running());
}

/// A flight whose only message was refused (a fix before its start) has a checkpoint without an
/// approval; after a restart the worker restores it as not started, and its start is taken.
TEST_F(NatsWorkers, AFlightWhoseMessagesWereAllRefusedStartsAfterARestart) {
  auto approver = worker("approve", "ap1");
  ASSERT_EQ(approve("a1").at("status"), "approved") << approver->log();
  const json rep = report("a1");
  auto first = worker("track", "tr1");
  const std::string subject = nats::fixSubject("acme", "f1");
  const auto of_f1 = [](const std::vector<json>& e, const std::string& type) {
    return static_cast<std::size_t>(std::count_if(e.begin(), e.end(), [&](const json& x) {
      return x.at("_subject") == nats::eventSubject("acme", "f1") && x.at("event") == type;
    }));
  };
  client_->publish(subject, fixAt(rep, 0).dump());
  std::vector<json> ev = waitFor([&](const std::vector<json>& e) { return of_f1(e, "rejected_input") >= 1; });
  ASSERT_EQ(of_f1(ev, "rejected_input"), 1u) << first->log();
  EXPECT_EQ(first->kill(SIGTERM), 0);  // a clean stop: the flight's checkpoint is written
  ASSERT_TRUE(client_->get(nats::kFlightBucket, "acme.f1").has_value());
  auto second = worker("track", "tr2");
  client_->publish(subject, json{{"start", {{"approval", "a1"}}}}.dump());
  client_->publish(subject, fixAt(rep, 1).dump());
  ev = waitFor([&](const std::vector<json>& e) { return of_f1(e, "fix") >= 1 || of_f1(e, "rejected_input") >= 2; });
  EXPECT_EQ(of_f1(ev, "flight_started"), 1u) << second->log();
  EXPECT_EQ(of_f1(ev, "fix"), 1u) << second->log();
  EXPECT_EQ(of_f1(ev, "rejected_input"), 1u);
}

/// Four flights, fixes published while the worker that holds the partitions is killed -9; a
/// second worker (running all along, its leases refused) takes them over from the checkpoints.
TEST_F(NatsWorkers, AKilledTrackWorkerIsReplacedAndEveryFixIsJudgedOnceWithNoEventLostOrDoubled) {
  auto approver = worker("approve", "ap1");
  ASSERT_EQ(approve("a1").at("status"), "approved");
  const json rep = report("a1");
  auto first = worker("track", "tr1");
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // tr1 holds every partition
  auto second = worker("track", "tr2");
  const std::vector<std::string> flights = {"f1", "f2", "f3", "f4", "f5", "f6"};
  constexpr int kFixes = 120;
  std::map<std::string, std::vector<std::string>> lines;
  for (const std::string& f : flights) {
    client_->publish(nats::fixSubject("acme", f), json{{"start", {{"approval", "a1"}}}}.dump());
    // PLs over the corridor now and then: violations and recoveries, judged the same every time.
    for (int k = 0; k < kFixes; ++k) lines[f].push_back(fixAt(rep, k, 0.0, (k / 10) % 3 == 1 ? 3.0 : 0.5).dump());
  }
  for (int k = 0; k < kFixes; ++k) {
    for (const std::string& f : flights) client_->publish(nats::fixSubject("acme", f), lines[f][static_cast<std::size_t>(k)]);
    if (k == kFixes / 3) {
      EXPECT_EQ(first->kill(SIGKILL), 128 + SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::vector<json> ev = waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= flights.size() * kFixes; }, 90);
  ASSERT_EQ(count(ev, "fix"), flights.size() * kFixes) << second->log();
  EXPECT_NE(second->log().find("holds partition"), std::string::npos);
  for (const std::string& f : flights) {
    std::vector<json> mine;
    std::set<std::uint64_t> judged;
    for (const json& e : ev) {
      if (e.at("_subject") != nats::eventSubject("acme", f) || e.at("event") == "flight_started") continue;
      if (e.at("event") == "fix") {
        EXPECT_TRUE(judged.insert(e.at("input_seq").get<std::uint64_t>()).second) << f << " judged twice";
      }
      mine.push_back(comparable(e));
    }
    const std::vector<json> expected = [&] {
      std::vector<json> x;
      for (const json& e : trackEvents("a1", f, lines[f])) x.push_back(comparable(e));
      return x;
    }();
    ASSERT_EQ(mine.size(), expected.size()) << f;
    for (std::size_t i = 0; i < mine.size(); ++i) EXPECT_EQ(mine[i], expected[i]) << f << " event " << i;
    EXPECT_GE(count(ev, "violation", f), 2u);
  }
}

/// The server killed -9 in the middle of a stream and restarted on its file store: every fix it
/// acknowledged is judged, once; the worker goes on by itself.
TEST_F(NatsWorkers, ARestartedServerLosesNothingAcknowledged) {
  auto approver = worker("approve", "ap1");
  ASSERT_EQ(approve("a1").at("status"), "approved");
  const json rep = report("a1");
  auto tracker = worker("track", "tr1");
  for (int i = 0; i < 100 && tracker->log().find("holds partition") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const std::string subject = nats::fixSubject("acme", "f1");
  client_->publish(subject, json{{"start", {{"approval", "a1"}}}}.dump());
  constexpr int kFixes = 80;
  int acknowledged = 0;
  for (int k = 0; k < kFixes; ++k) {
    if (k == kFixes / 2) {
      server_->kill();
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      server_->start();
    }
    // A publisher retries with the same message id until acknowledged: a repeat is dropped.
    for (int attempt = 0; attempt < 100; ++attempt) {
      try {
        client_->publish(subject, fixAt(rep, k).dump(), "fix-f1-" + std::to_string(k));
        ++acknowledged;
        break;
      } catch (const service::NatsError&) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    }
  }
  ASSERT_EQ(acknowledged, kFixes);
  const std::vector<json> ev = waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= kFixes; }, 60);
  EXPECT_EQ(count(ev, "fix"), static_cast<std::size_t>(kFixes)) << tracker->log();
  EXPECT_EQ(count(ev, "rejected_input"), 0u);
  EXPECT_TRUE(tracker->running());
}

TEST_F(NatsWorkers, DuplicateAndOutOfOrderFixesAreRejectedAndARepeatedMessageIdIsDropped) {
  auto approver = worker("approve", "ap1");
  ASSERT_EQ(approve("a1").at("status"), "approved");
  const json rep = report("a1");
  auto tracker = worker("track", "tr1");
  const std::string subject = nats::fixSubject("acme", "f1");
  client_->publish(subject, json{{"start", {{"approval", "a1"}}}}.dump());
  for (int k = 0; k < 10; ++k) client_->publish(subject, fixAt(rep, k).dump(), "fix-" + std::to_string(k));
  const std::uint64_t before = client_->lastSequence(nats::kFixStream);
  EXPECT_EQ(client_->publish(subject, fixAt(rep, 9).dump(), "fix-9"), before);  // the same id again: not stored
  client_->publish(subject, fixAt(rep, 9).dump());                               // the same fix, a new message
  client_->publish(subject, fixAt(rep, 4).dump());                               // an older one
  client_->publish(subject, fixAt(rep, 10).dump());
  const std::vector<json> ev = waitFor([](const std::vector<json>& e) { return count(e, "fix") >= 11 && count(e, "rejected_input") >= 2; });
  EXPECT_EQ(count(ev, "fix"), 11u);
  ASSERT_EQ(count(ev, "rejected_input"), 2u);
  for (const json& e : ev) {
    if (e.at("event") == "rejected_input") {
      EXPECT_EQ(e.at("subject"), subject);
    }
  }
}

/// A zone set's new version, put while two workers track four flights made from it: every fix
/// published after the put is judged against it (its events name the version), a closure it adds
/// on the route ahead gives a zone violation naming it, and the fixes before name the old version.
/// Puts a zone set file as the authority's set "zurich" (`skylane nats zones`); its version.
std::uint64_t putZurich(const std::string& url, const std::string& file) {
  const test::CommandResult r = test::runCommand(std::string(SKYLANE_BINARY) + " nats zones " + file + " --nats " + url +
                                                 " --owner authority --set zurich");
  EXPECT_EQ(r.status, 0) << r.out;
  return r.status == 0 ? json::parse(r.out).at("version").get<std::uint64_t>() : 0;
}

/// The example mission with its zones from the zone set authority.zurich, as a file in `dir`.
std::string zurichMission(const std::string& dir) {
  const std::string examples = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/";
  json mission = json::parse(std::ifstream(examples + "mission.json"));
  mission.erase("zones");
  mission["zonesets"] = {"authority.zurich"};
  for (auto& o : mission["orbits"]) o = examples + o.get<std::string>();
  mission["buildings"] = examples + mission["buildings"].get<std::string>();
  std::ofstream(dir + "/mission.json") << mission.dump();
  return dir + "/mission.json";
}


ZurichFlights NatsWorkers::startZurichFlights(bool second_worker) {
  ZurichFlights z;
  z.v1 = putZurich(server_->url(), std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json");
  auto approver = worker("approve", "ap1");
  const json st = approve("a1", zurichMission(dir_));
  EXPECT_EQ(st.at("status"), "approved") << approver->log();
  if (st.at("status") != "approved") return z;
  z.rep = report("a1");
  z.w1 = worker("track", "tr1");
  if (second_worker) z.w2 = worker("track", "tr2");
  for (const std::string& f : z.flights) client_->publish(nats::fixSubject("acme", f), json{{"start", {{"approval", "a1"}}}}.dump());
  return z;
}

TEST_F(NatsWorkers, AZoneSetUpdateIsInForceForEveryFixPublishedAfterIt) {
  const std::string examples = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/";
  const auto put = [&](const std::string& file) { return putZurich(server_->url(), file); };
  ZurichFlights z = startZurichFlights();
  ASSERT_FALSE(z.rep.is_null());
  const std::uint64_t v1 = z.v1;
  const json& rep = z.rep;
  const auto& w1 = z.w1;
  const auto& w2 = z.w2;
  const std::vector<std::string>& flights = z.flights;
  for (int k = 0; k < 10; ++k) {
    for (const std::string& f : flights) client_->publish(nats::fixSubject("acme", f), fixAt(rep, k).dump());
  }
  (void)waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= 40; });
  // Version 2: the same zones and a closure 120 m wide around the route 25 s after departure.
  std::ofstream(dir_ + "/zones_v2.json") << test::withClosureAt(json::parse(std::ifstream(examples + "zones_ed269.json")), fixAt(rep, 25)).dump();
  const std::uint64_t v2 = put(dir_ + "/zones_v2.json");
  const auto t_put = std::chrono::steady_clock::now();
  for (int k = 10; k < 30; ++k) {
    for (const std::string& f : flights) client_->publish(nats::fixSubject("acme", f), fixAt(rep, k).dump());
  }
  const std::vector<json> ev = waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= 120; });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_put).count();
  ASSERT_EQ(count(ev, "fix"), 120u) << w1->log() << w2->log();
  for (const json& e : ev) {
    if (e.at("event") != "fix") continue;
    const int k = static_cast<int>(std::lround(*maps::parseRfc3339(e.at("time").get<std::string>()) - *maps::parseRfc3339(rep.at("departure").get<std::string>())));
    EXPECT_EQ(e.at("zonesets").at("authority.zurich").get<std::uint64_t>(), k < 10 ? v1 : v2) << e.dump();
  }
  for (const std::string& f : flights) {
    const bool named = std::any_of(ev.begin(), ev.end(), [&](const json& e) {
      return e.at("event") == "violation" && e.value("flight", "") == f && e.dump().find("EX-NEW-CLOSURE") != std::string::npos;
    });
    EXPECT_TRUE(named) << f << [&] {
      std::string all;
      for (const json& e : ev) {
        if (e.value("flight", "") == f && e.at("event") != "fix") all += e.dump() + "\n";
      }
      for (const json& e : ev) {
        if (e.value("flight", "") == f && e.at("event") == "fix" && e.at("time") > "2020-01-01T14:00:23") all += e.dump().substr(0, 900) + "\n";
      }
      return all;
    }();
  }
  EXPECT_LT(seconds, 30.0);
  // A version the fence cannot use, put straight into the bucket (no CLI validation): rejected by
  // name, and the fixes after it are still judged against version 2.
  const std::uint64_t v3 = client_->put(nats::kZoneSetBucket, "authority.zurich", "{\"UASZoneList\": [{\"identifier\": 3}]}");
  for (const std::string& f : flights) client_->publish(nats::fixSubject("acme", f), fixAt(rep, 30).dump());
  const std::vector<json> after = waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= 124 && count(e, "rejected_input") >= 1; });
  ASSERT_EQ(count(after, "fix"), 124u);
  const auto departure = *maps::parseRfc3339(rep.at("departure").get<std::string>());
  std::size_t judged_after = 0;
  for (const json& e : after) {
    if (e.at("event") == "fix" && *maps::parseRfc3339(e.at("time").get<std::string>()) - departure > 29.5) {
      EXPECT_EQ(e.at("zonesets").at("authority.zurich"), v2);
      ++judged_after;
    }
    if (e.at("event") == "rejected_input") {
      EXPECT_EQ(e.at("subject"), "$KV.skylane_zonesets.authority.zurich");
      EXPECT_NE(e.at("error").get<std::string>().find("version " + std::to_string(v3) + " not taken"), std::string::npos) << e.dump();
    }
  }
  EXPECT_EQ(judged_after, flights.size());
  EXPECT_NE((w1->log() + w2->log()).find("zone set authority.zurich version " + std::to_string(v2) + " in force"), std::string::npos);
  // Both workers stop; a new one (an empty cache: the approval's bundle names version 1) takes
  // every partition. The newest version is still unusable: it goes back to version 2, the newest
  // usable one, as the others had — not to the bundle's version 1.
  EXPECT_EQ(w1->kill(SIGTERM), 0);
  EXPECT_EQ(w2->kill(SIGTERM), 0);
  auto w3 = worker("track", "tr3");
  for (const std::string& f : flights) client_->publish(nats::fixSubject("acme", f), fixAt(rep, 31).dump());
  const std::vector<json> late = waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= 128; });
  ASSERT_EQ(count(late, "fix"), 128u) << w3->log();
  for (const json& e : late) {
    if (e.at("event") == "fix" && *maps::parseRfc3339(e.at("time").get<std::string>()) - departure > 30.5) {
      EXPECT_EQ(e.at("zonesets").at("authority.zurich"), v2) << w3->log();
    }
  }
}

TEST_F(NatsWorkers, AZoneSetUpdateReachesQuietWorkersAndEachFlightIsToldWithoutAFix) {
  const std::string examples = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/";
  ZurichFlights z = startZurichFlights();
  ASSERT_FALSE(z.rep.is_null());
  const auto& w1 = z.w1;
  const auto& w2 = z.w2;
  const std::vector<std::string>& flights = z.flights;
  for (const std::string& f : flights) client_->publish(nats::fixSubject("acme", f), fixAt(z.rep, 0).dump());
  (void)waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= flights.size(); });
  // Both workers hold flights (the partitions are shared out), then no fix comes.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto t_put = std::chrono::steady_clock::now();
  const std::uint64_t v2 = putZurich(server_->url(), examples + "zones_ed269.json");
  const std::vector<json> ev = waitFor([&](const std::vector<json>& e) { return count(e, "zoneset_in_force") >= flights.size(); }, 30);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_put).count();
  ASSERT_EQ(count(ev, "zoneset_in_force"), flights.size()) << w1->log() << w2->log();
  for (const json& e : ev) {
    if (e.at("event") != "zoneset_in_force") continue;
    EXPECT_EQ(e.at("zoneset"), "authority.zurich");
    EXPECT_EQ(e.at("version"), v2);
  }
  EXPECT_EQ(count(ev, "fix"), flights.size());  // no fix was needed for it
  std::printf("zone set version in force at every quiet worker after %.3f s (the workers look every 0.25 s)\n", seconds);
  EXPECT_LT(seconds, 10.0);  // 1 s on a quiet machine; the margin is for a loaded test run
}

/// Partitions handed over with quiet flights: the worker taking them loads their flights at once,
/// so a zone set version put then is told to each; a version put while no worker runs is told to
/// each flight by the worker that starts next — no fix needed either time.
TEST_F(NatsWorkers, FlightsOfAPartitionTakenOverAreToldOfZoneSetVersionsWithoutAFix) {
  const std::string examples = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/";
  ZurichFlights z = startZurichFlights(false);
  ASSERT_FALSE(z.rep.is_null());
  for (const std::string& f : z.flights) client_->publish(nats::fixSubject("acme", f), fixAt(z.rep, 0).dump());
  (void)waitFor([&](const std::vector<json>& e) { return count(e, "fix") >= z.flights.size(); });
  // A second worker takes half the partitions from the first, whose flights are quiet.
  auto w2 = worker("track", "tr2");
  const auto holds = [](const std::string& log) {
    std::size_t n = 0;
    for (std::size_t at = log.find("holds partition"); at != std::string::npos; at = log.find("holds partition", at + 1)) ++n;
    return n;
  };
  for (int i = 0; i < 300 && holds(w2->log()) < kPartitions / 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_EQ(holds(w2->log()), static_cast<std::size_t>(kPartitions / 2)) << w2->log();
  const std::uint64_t v2 = putZurich(server_->url(), examples + "zones_ed269.json");
  const auto told = [&](const std::vector<json>& e, std::uint64_t v) {
    return static_cast<std::size_t>(std::count_if(e.begin(), e.end(), [&](const json& x) { return x.at("event") == "zoneset_in_force" && x.at("version") == v; }));
  };
  std::vector<json> ev = waitFor([&](const std::vector<json>& e) { return told(e, v2) >= z.flights.size(); }, 30);
  ASSERT_EQ(told(ev, v2), z.flights.size()) << z.w1->log() << w2->log();
  // Both stop; version 3 is put while no worker runs; the next worker tells every flight.
  EXPECT_EQ(z.w1->kill(SIGTERM), 0);
  EXPECT_EQ(w2->kill(SIGTERM), 0);
  std::ofstream(dir_ + "/zones_v3.json") << test::withClosureAt(json::parse(std::ifstream(examples + "zones_ed269.json")), fixAt(z.rep, 25)).dump();
  const std::uint64_t v3 = putZurich(server_->url(), dir_ + "/zones_v3.json");
  auto w3 = worker("track", "tr3");
  ev = waitFor([&](const std::vector<json>& e) { return told(e, v3) >= z.flights.size(); }, 30);
  EXPECT_EQ(told(ev, v3), z.flights.size()) << w3->log();
  std::set<std::string> flights;
  for (const json& e : ev) {
    if (e.at("event") == "zoneset_in_force" && e.at("version") == v3) flights.insert(e.at("flight").get<std::string>());
  }
  EXPECT_EQ(flights.size(), z.flights.size());
  EXPECT_EQ(count(ev, "fix"), z.flights.size());  // no fix was needed
}

/// The partition a worker computes for a flight (to load a taken partition's flights at once) is
/// the one nats-server's mapping sends its fixes to: 300 ids of 1–64 characters, 4 and 37 partitions.
TEST_F(NatsWorkers, AFlightsPartitionIsTheOneTheServersMappingSendsItsFixesTo) {
  NatsServer wide(std::filesystem::path(dir_) / "server37", 37);
  ASSERT_EQ(test::runCommand(std::string(SKYLANE_BINARY) + " nats setup --nats " + wide.url() + " --partitions 37").status, 0);
  NatsClient wide_client(wide.url(), "test");
  const std::string chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
  std::uint32_t state = 12345;
  const auto next = [&] { return state = state * 1103515245u + 12345u, (state >> 8); };
  std::vector<std::pair<std::string, std::string>> ids;
  for (int i = 0; i < 300; ++i) {
    std::string op(1 + next() % 64, 'a'), flight(1 + next() % 64, 'a');
    for (char& c : op) c = chars[next() % 62];  // an id does not start with '_'
    for (std::size_t k = 1; k < flight.size(); ++k) flight[k] = chars[next() % chars.size()];
    ids.emplace_back(op, flight);
  }
  for (auto [client, partitions] : {std::pair<NatsClient*, int>{client_.get(), kPartitions}, {&wide_client, 37}}) {
    for (const auto& [op, flight] : ids) (void)client->publish(nats::fixSubject(op, flight), "{}");
    std::set<int> seen;
    for (std::uint64_t s = 1; s <= ids.size(); ++s) {
      const auto m = client->message(nats::kFixStream, s);
      ASSERT_TRUE(m.has_value());
      const std::vector<std::string> t = nats::subjectTokens(m->subject);
      ASSERT_EQ(t.size(), 5u) << m->subject;
      EXPECT_EQ(std::stoi(t[2]), nats::partitionOf(t[3], t[4], partitions)) << m->subject;
      EXPECT_EQ(t[3], ids[s - 1].first);
      seen.insert(std::stoi(t[2]));
    }
    EXPECT_EQ(seen.size(), static_cast<std::size_t>(partitions));  // every partition is reached (no constant answer)
  }
}

TEST_F(NatsWorkers, TwoApproveWorkersDoEachRequestOnceAndABadRequestIsInvalidByName) {
  auto a = worker("approve", "ap1");
  auto b = worker("approve", "ap2");
  const std::string mission = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json";
  std::vector<std::thread> requests;
  std::vector<json> outcomes(4);
  for (int i = 0; i < 4; ++i) requests.emplace_back([&, i] { outcomes[static_cast<std::size_t>(i)] = approve("r" + std::to_string(i)); });
  for (auto& t : requests) t.join();
  for (const json& o : outcomes) EXPECT_EQ(o.at("status"), "approved") << o.dump();
  // The same request again: its outcome stands, no second approval.
  EXPECT_EQ(approve("r0").at("status"), "approved");
  // A mission without its vehicle: invalid, the message names the field.
  json bad = json::parse(std::ifstream(mission));
  bad.erase("vehicle");
  for (auto& z : bad["zones"]) z = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/" + z.get<std::string>();
  for (auto& o : bad["orbits"]) o = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/" + o.get<std::string>();
  bad["buildings"] = std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/" + bad["buildings"].get<std::string>();
  std::ofstream(dir_ + "/bad.json") << bad.dump();
  // `skylane nats approve` checks the mission before it sends it: exit 2 naming the field.
  const test::CommandResult refused = test::runCommand(std::string(SKYLANE_BINARY) + " nats approve " + dir_ + "/bad.json --nats " +
                                                       server_->url() + " --operator acme --id bad 2>&1");
  EXPECT_EQ(refused.status, 2) << refused.out;
  EXPECT_NE(refused.out.find("$.vehicle"), std::string::npos) << refused.out;
  // Sent anyway (another client): the approve worker finds it invalid, by name.
  client_->publish(nats::approvalSubject("acme", "bad"), service::bundleText(service::packMission(dir_ + "/bad.json")));
  json invalid;
  for (int i = 0; i < 600 && (invalid.is_null() || invalid.at("status") == "running"); ++i) {
    if (const auto e = client_->get(nats::kApprovalBucket, "acme.bad")) invalid = json::parse(e->value);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_FALSE(invalid.is_null());
  EXPECT_EQ(invalid.at("status"), "invalid");
  EXPECT_NE(invalid.value("message", "").find("vehicle"), std::string::npos) << invalid.dump();
  const std::vector<json> ev = events();
  for (const char* id : {"r0", "r1", "r2", "r3", "bad"}) {
    EXPECT_EQ(std::count_if(ev.begin(), ev.end(), [&](const json& e) { return e.at("event") == "approval" && e.at("id") == id; }), 1) << id;
  }
  EXPECT_EQ(client_->pending(nats::kApprovalStream, "approvers"), 0u);
}

}  // namespace
}  // namespace skylane
