// `skylane serve --nats` in front of the JetStream workers, all real processes: nats-server with
// a file store on a loopback port, an approve worker, a track worker and the service. The HTTP
// API is the embedded service's; approvals are computed by the approve worker, fixes judged by
// the track worker, and the events come back as Server-Sent Events whose ids are the event
// stream's sequence numbers. Checked against `skylane track` run on the same approval and fixes.

#include "maps/time.hpp"
#include "tests/service/child_process.hpp"
#include "tests/service/http_client.hpp"
#include "tests/service/route_fix.hpp"
#include "tests/service/service_process.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <fstream>
#include <sstream>
#include <thread>

namespace skylane {
namespace {

using nlohmann::json;
using test::ChildProcess;
using test::HttpClient;
using test::HttpReply;
using test::NatsServer;
using test::ServiceProcess;
using test::TestTokens;

const std::string kJson = "Content-Type: application/json";
const std::string kNdjson = "Content-Type: application/x-ndjson";

std::string auth(const char* token) { return std::string("Authorization: ") + token; }

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// One Server-Sent Event.
struct Sse {
  long long id = 0;
  std::string type;
  json data;
};

/// The events of a stream's text so far.
std::vector<Sse> parseSse(const std::string& text) {
  std::vector<Sse> out;
  std::istringstream in(text);
  Sse e;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("id: ", 0) == 0) e.id = std::stoll(line.substr(4));
    if (line.rfind("event: ", 0) == 0) e.type = line.substr(7);
    if (line.rfind("data: ", 0) == 0) e.data = json::parse(line.substr(6));
    if (line.empty() && e.id > 0) {
      out.push_back(e);
      e = Sse{};
    }
  }
  return out;
}

/// An event without what names the input, wall-clock times and the zone set versions (which
/// `skylane track` on a file does not have).
json comparable(json e) {
  for (const char* k : {"line", "source", "report", "error", "planning_time_s", "operator", "input_seq", "subject", "zonesets"}) e.erase(k);
  return e;
}

class ServeOnNats : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!NatsServer::installed()) GTEST_SKIP() << "nats-server is not installed (scripts/setup.sh installs it)";
    dir_ = test::scratchPath("serve-nats-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    nats_ = std::make_unique<NatsServer>(std::filesystem::path(dir_) / "server", 2);
    const test::CommandResult setup =
        test::runCommand(std::string(SKYLANE_BINARY) + " nats setup --nats " + nats_->url() + " --partitions 2");
    ASSERT_EQ(setup.status, 0) << setup.out;
    approver_ = worker("approve", "ap1");
    tracker_ = worker("track", "tr1");
    service_ = std::make_unique<ServiceProcess>(std::filesystem::path(dir_) / "service", std::vector<std::string>{"--nats", nats_->url()});
    client_ = std::make_unique<HttpClient>(service_->port());
  }
  std::unique_ptr<ChildProcess> worker(const std::string& role, const std::string& name) {
    return std::make_unique<ChildProcess>(
        std::vector<std::string>{SKYLANE_BINARY, "worker", "--nats", nats_->url(), "--role", role, "--name", name, "--partitions", "all",
                                 "--cache", dir_ + "/cache-" + name, "--work", dir_ + "/work-" + name},
        dir_ + "/" + name + ".log");
  }
  HttpReply call(const std::string& method, const std::string& target, const char* token, const std::string& body = {},
                 const std::string& type = kJson) {
    std::vector<std::string> h = {auth(token)};
    if (!body.empty()) h.push_back(type);
    return client_->request(method, target, body, h);
  }
  /// The example mission with the published zone set and no files of its own.
  std::string mission() const {
    json m = json::parse(readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json"));
    for (const char* k : {"zones", "buildings", "orbits"}) m.erase(k);
    m["zonesets"] = {zoneset_};
    return m.dump();
  }
  /// The example zones published, the example mission submitted by acme; its final status.
  json approve() {
    const HttpReply z = call("POST", "/v1/zonesets?name=zurich", TestTokens::kAuthority,
                             readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json"));
    EXPECT_EQ(z.status, 201) << z.body;
    zoneset_ = json::parse(z.body).at("id");
    const HttpReply r = call("POST", "/v1/approvals", TestTokens::kAcme, mission());
    EXPECT_EQ(r.status, 202) << r.body;
    approval_ = json::parse(r.body).at("id");
    json st;
    for (int i = 0; i < 3000; ++i) {
      st = json::parse(call("GET", "/v1/approvals/" + approval_, TestTokens::kAcme).body);
      if (st.at("status") != "queued" && st.at("status") != "running") break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return st;
  }
  static json fixAt(const json& rep, int k, double off_m = 0.0) { return test::fixAlongRoute(rep, k, off_m); }
  /// `skylane track` on the approval's report (as the service serves it) and `body`'s fixes.
  std::vector<json> trackEvents(const std::string& flight, const std::string& body) {
    const std::string report = dir_ + "/report.json", fixes = dir_ + "/fixes.jsonl";
    std::ofstream(report) << call("GET", "/v1/approvals/" + approval_ + "/report.json", TestTokens::kAcme).body;
    std::ofstream(fixes) << body;
    const test::CommandResult cli =
        test::runCommand(std::string(SKYLANE_BINARY) + " track --approval " + flight + "=" + report + " --input " + fixes + " 2>/dev/null");
    std::vector<json> out;
    std::istringstream in(cli.out);
    for (std::string line; std::getline(in, line);) {
      if (!line.empty()) out.push_back(json::parse(line));
    }
    return out;
  }
  std::string dir_, approval_, zoneset_;
  std::unique_ptr<NatsServer> nats_;
  std::unique_ptr<ChildProcess> approver_, tracker_;
  std::unique_ptr<ServiceProcess> service_;
  std::unique_ptr<HttpClient> client_;
};

TEST_F(ServeOnNats, TheWorkersApproveAndTrackAndTheEventsStreamWithStreamSequenceIds) {
  const json st = approve();
  ASSERT_EQ(st.at("status"), "approved") << st.dump() << approver_->log();
  // The approve worker's outputs are served as the embedded service serves its own.
  for (const char* f : {"report.json", "route.geojson", "operational_intent.json", "mission.plan"}) {
    EXPECT_TRUE(st.at("files").contains(f)) << st.dump();
    EXPECT_EQ(call("GET", "/v1/approvals/" + approval_ + "/" + f, TestTokens::kAcme).status, 200) << f;
  }
  const json rep = json::parse(call("GET", "/v1/approvals/" + approval_ + "/report.json", TestTokens::kAcme).body);
  const HttpReply started = call("POST", "/v1/flights", TestTokens::kAcme, json{{"approval", approval_}}.dump());
  ASSERT_EQ(started.status, 201) << started.body;
  const std::string fl = json::parse(started.body).at("id");
  HttpClient live(service_->port());
  live.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme)});
  ASSERT_TRUE(live.waitFor("retry: 1000", 2000)) << live.streamed();
  // On the route, then 40 m off it (a level-1 violation: a replan), then a bad line.
  std::string body;
  for (int k = 0; k < 30; ++k) body += fixAt(rep, k, k >= 12 && k < 20 ? 40.0 : 0.0).dump() + "\n";
  body += "{\"time\": 3}\n";
  const HttpReply posted = call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, body, kNdjson);
  ASSERT_EQ(posted.status, 200) << posted.body;
  EXPECT_EQ(json::parse(posted.body).at("accepted"), 30);
  EXPECT_EQ(json::parse(posted.body).at("rejected"), 1);
  std::vector<Sse> got;
  for (int i = 0; i < 600; ++i) {
    got = parseSse(live.streamed());
    if (std::count_if(got.begin(), got.end(), [](const Sse& e) { return e.type == "fix"; }) >= 30) break;
    live.readFor(100);
  }
  // The same events as `skylane track` on the same approval and fixes (the line refused at the
  // door comes first here, last there), with rising stream sequences as ids.
  std::vector<json> mine, rejected;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(got[i].id, got[i - 1].id);
    }
    EXPECT_EQ(got[i].type, got[i].data.at("event"));
    if (got[i].type == "flight_started") continue;
    if (got[i].type == "fix") {  // judged against the zone set the mission named, followed by its NATS key
      EXPECT_TRUE(got[i].data.at("zonesets").contains("authority." + zoneset_)) << got[i].data.dump();
    }
    (got[i].type == "rejected_input" ? rejected : mine).push_back(comparable(got[i].data));
  }
  std::vector<json> expected, expected_rejected;
  for (const json& e : trackEvents(fl, body)) (e.at("event") == "rejected_input" ? expected_rejected : expected).push_back(comparable(e));
  ASSERT_EQ(mine.size(), expected.size()) << live.streamed() << tracker_->log();
  for (std::size_t i = 0; i < mine.size(); ++i) EXPECT_EQ(mine[i], expected[i]) << i;
  // The refused line names the flight it was posted to (as the embedded service's does) and why.
  ASSERT_EQ(rejected.size(), 1u);
  EXPECT_EQ(rejected[0].at("flight"), fl);
  rejected[0].erase("flight");
  EXPECT_EQ(rejected[0], expected_rejected.at(0));
  const auto refused = std::find_if(got.begin(), got.end(), [](const Sse& e) { return e.type == "rejected_input"; });
  EXPECT_NE(refused->data.at("error").get<std::string>().find("$.time"), std::string::npos) << refused->data.dump();
  const auto replans = std::count_if(mine.begin(), mine.end(), [](const json& e) { return e.at("event") == "replan"; });
  EXPECT_GE(replans, 1);
  // The flight's state and route from the track worker's checkpoint (written every 2 s).
  json flight;
  for (int i = 0; i < 100; ++i) {
    flight = json::parse(call("GET", "/v1/flights/" + fl, TestTokens::kAcme).body);
    if (flight.at("state").value("checkpoint_fix_seq", 0) > 0 && flight.at("state").value("route_version", 0) == replans) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(flight.at("state").at("route_version"), replans) << flight.dump();
  const json route = json::parse(call("GET", "/v1/flights/" + fl + "/route", TestTokens::kAcme).body);
  EXPECT_EQ(route.at("features").at(0).at("properties").at("route_version"), replans) << route.dump().substr(0, 400);
  // A reader of all acme's flights resumed after the 10th event gets exactly the rest, from the
  // stream; another operator's reader gets none of them.
  HttpClient resumed(service_->port());
  resumed.openStream("/v1/events", {auth(TestTokens::kAcme), "Last-Event-ID: " + std::to_string(got.at(9).id)});
  ASSERT_TRUE(resumed.waitFor("id: " + std::to_string(got.back().id) + "\n", 5000)) << resumed.streamed();
  const std::vector<Sse> rest = parseSse(resumed.streamed());
  ASSERT_EQ(rest.size(), got.size() - 10);
  for (std::size_t i = 0; i < rest.size(); ++i) EXPECT_EQ(rest[i].id, got[10 + i].id);
  HttpClient other(service_->port());
  other.openStream("/v1/events", {auth(TestTokens::kOther), "Last-Event-ID: 0"});
  other.readFor(500);
  EXPECT_EQ(other.streamed().find("id: "), std::string::npos) << other.streamed();
}

TEST_F(ServeOnNats, AServiceKilledAndRestartedKeepsItsApprovalsFlightsAndTheEventStream) {
  ASSERT_EQ(approve().at("status"), "approved") << approver_->log();
  const json rep = json::parse(call("GET", "/v1/approvals/" + approval_ + "/report.json", TestTokens::kAcme).body);
  const std::string fl = json::parse(call("POST", "/v1/flights", TestTokens::kAcme, json{{"approval", approval_}}.dump()).body).at("id");
  std::string first, second;
  for (int k = 0; k < 10; ++k) first += fixAt(rep, k).dump() + "\n";
  for (int k = 10; k < 20; ++k) second += fixAt(rep, k).dump() + "\n";
  ASSERT_EQ(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, first, kNdjson).status, 200);
  // A second approval is queued, and the service killed before the worker is done with it.
  const HttpReply second_approval = call("POST", "/v1/approvals", TestTokens::kAcme, mission());
  ASSERT_EQ(second_approval.status, 202) << second_approval.body;
  const std::string queued = json::parse(second_approval.body).at("id");
  EXPECT_EQ(service_->kill(SIGKILL), 128 + SIGKILL);
  // While the service is down the workers go on: these fixes come in by another front (the CLI).
  std::ofstream(dir_ + "/second.jsonl") << second;
  const test::CommandResult pub = test::runCommand(std::string(SKYLANE_BINARY) + " nats publish " + dir_ + "/second.jsonl --nats " +
                                                   nats_->url() + " --operator acme --flight " + fl + " 2>&1");
  ASSERT_EQ(pub.status, 0) << pub.out;
  service_->start({"--nats", nats_->url()});
  client_ = std::make_unique<HttpClient>(service_->port());
  EXPECT_EQ(json::parse(call("GET", "/v1/approvals/" + approval_, TestTokens::kAcme).body).at("status"), "approved");
  // The approval left queued is taken from the workers' outcome (or asked again), not lost.
  json st;
  for (int i = 0; i < 3000; ++i) {
    st = json::parse(call("GET", "/v1/approvals/" + queued, TestTokens::kAcme).body);
    if (st.at("status") != "queued" && st.at("status") != "running") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(st.at("status"), "approved") << st.dump() << approver_->log();
  EXPECT_EQ(call("GET", "/v1/approvals/" + queued + "/report.json", TestTokens::kAcme).status, 200);
  HttpClient resumed(service_->port());
  resumed.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme), "Last-Event-ID: 0"});
  std::vector<Sse> got;
  for (int i = 0; i < 600; ++i) {
    got = parseSse(resumed.streamed());
    if (std::count_if(got.begin(), got.end(), [](const Sse& e) { return e.type == "fix"; }) >= 20) break;
    resumed.readFor(100);
  }
  // Every fix judged once, in order, by the one track worker, whichever front published it.
  std::vector<double> times;
  const maps::GpsTime departure = *maps::parseRfc3339(rep.at("departure").get<std::string>());
  for (const Sse& e : got) {
    if (e.type == "fix") times.push_back(*maps::parseRfc3339(e.data.at("time").get<std::string>()) - departure);
  }
  ASSERT_EQ(times.size(), 20u) << resumed.streamed();
  for (int k = 0; k < 20; ++k) EXPECT_NEAR(times[k], k, 1e-6) << k;
  EXPECT_TRUE(tracker_->running());
}

TEST_F(ServeOnNats, AZoneSetVersionUploadedToTheServiceIsInForceForTheFlightsOnTheWorkers) {
  ASSERT_EQ(approve().at("status"), "approved") << approver_->log();
  const json rep = json::parse(call("GET", "/v1/approvals/" + approval_ + "/report.json", TestTokens::kAcme).body);
  const std::string fl = json::parse(call("POST", "/v1/flights", TestTokens::kAcme, json{{"approval", approval_}}.dump()).body).at("id");
  HttpClient live(service_->port());
  live.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme)});
  ASSERT_TRUE(live.waitFor("retry: 1000", 2000));
  std::string first;
  for (int k = 0; k < 10; ++k) first += fixAt(rep, k).dump() + "\n";
  ASSERT_EQ(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, first, kNdjson).status, 200);
  for (int i = 0; i < 300; ++i) {  // judged (the answer says they are kept, not yet judged)
    const std::vector<Sse> ev = parseSse(live.streamed());
    if (std::count_if(ev.begin(), ev.end(), [](const Sse& e) { return e.type == "fix"; }) >= 10) break;
    live.readFor(100);
  }
  // Version 2 through the service: the same zones and a closure 120 m wide around the route 25 s
  // after departure. The mission named the set without a version, so the flight follows it.
  const json zones = test::withClosureAt(json::parse(readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json")), fixAt(rep, 25));
  const HttpReply v2 = call("PUT", "/v1/zonesets/" + zoneset_, TestTokens::kAuthority, zones.dump());
  ASSERT_EQ(v2.status, 200) << v2.body;
  // The quiet track worker takes it and tells the flight, with no fix sent.
  ASSERT_TRUE(live.waitFor("event: zoneset_in_force", 10000)) << live.streamed() << tracker_->log();
  std::string second;
  for (int k = 10; k < 30; ++k) second += fixAt(rep, k).dump() + "\n";
  ASSERT_EQ(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, second, kNdjson).status, 200);
  std::vector<Sse> got;
  for (int i = 0; i < 300; ++i) {
    got = parseSse(live.streamed());
    if (std::count_if(got.begin(), got.end(), [](const Sse& e) { return e.type == "fix"; }) >= 30) break;
    live.readFor(100);
  }
  std::set<std::uint64_t> versions_before, versions_after;
  bool closure_named = false;
  for (const Sse& e : got) {
    if (e.type == "fix") {
      const int k = static_cast<int>(std::lround(*maps::parseRfc3339(e.data.at("time").get<std::string>()) -
                                                 *maps::parseRfc3339(rep.at("departure").get<std::string>())));
      (k < 10 ? versions_before : versions_after).insert(e.data.at("zonesets").at("authority." + zoneset_).get<std::uint64_t>());
    }
    closure_named = closure_named || (e.type == "violation" && e.data.dump().find("EX-NEW-CLOSURE") != std::string::npos);
  }
  ASSERT_EQ(versions_before.size(), 1u) << live.streamed();
  ASSERT_EQ(versions_after.size(), 1u);
  EXPECT_GT(*versions_after.begin(), *versions_before.begin());
  EXPECT_TRUE(closure_named) << live.streamed();
}

TEST_F(ServeOnNats, WhatCannotWorkOnNatsIsRefusedAtStartByName) {
  const std::string serve = "timeout 30 " + std::string(SKYLANE_BINARY) + " serve --port 0 --web none --nats " + nats_->url();
  // A fix input of the service's own: with --nats the fixes go to the workers.
  const test::CommandResult input = test::runCommand(serve + " --db " + dir_ + "/a.sqlite --tokens " + dir_ +
                                                     "/service/tokens.json --input jsonl:udp://127.0.0.1:0 2>&1");
  EXPECT_EQ(input.status, 2) << input.out;
  EXPECT_NE(input.out.find("--input"), std::string::npos) << input.out;
  // An operator whose name cannot be a subject token.
  std::ofstream(dir_ + "/tokens.json") << R"({"tokens": [{"sha256": ")" << std::string(64, 'a') << R"(", "operator": "acme.east"}]})";
  const test::CommandResult op = test::runCommand(serve + " --db " + dir_ + "/b.sqlite --tokens " + dir_ + "/tokens.json 2>&1");
  EXPECT_EQ(op.status, 2) << op.out;
  EXPECT_NE(op.out.find("\"acme.east\""), std::string::npos) << op.out;
  // No NATS server there.
  const test::CommandResult none = test::runCommand("timeout 30 " + std::string(SKYLANE_BINARY) + " serve --port 0 --web none --nats nats://127.0.0.1:1 --db " +
                                                    dir_ + "/c.sqlite --tokens " + dir_ + "/service/tokens.json 2>&1");
  EXPECT_EQ(none.status, 2) << none.out;
  EXPECT_NE(none.out.find("--nats nats://127.0.0.1:1"), std::string::npos) << none.out;
}

}  // namespace
}  // namespace skylane
