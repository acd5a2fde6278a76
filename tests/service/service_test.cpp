// `skylane serve` run as a process on a loopback port and used over HTTP: the error contract,
// authentication and the operators' separation (every route without a token, every cross-operator
// access), the approval → flight → fixes → events path against `skylane track` run on the same
// approval and fixes, event streams resumed with Last-Event-ID, rate and queue limits, malformed
// and oversized requests, and a kill -9 in the middle of a stream of fixes.

#include "maps/time.hpp"
#include "tests/service/http_client.hpp"
#include "tests/service/route_fix.hpp"
#include "tests/service/service_process.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <fstream>
#include <thread>

namespace skylane {
namespace {

using nlohmann::json;
using test::HttpClient;
using test::HttpReply;
using test::ServiceProcess;
using test::TestTokens;
using test::freeUdpPort;

std::string auth(const char* token) { return std::string("Authorization: ") + token; }
const std::string kJson = "Content-Type: application/json";
const std::string kNdjson = "Content-Type: application/x-ndjson";

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The bundled example mission with its zones by zone set id and no server-side files.
std::string exampleMission(const std::string& zoneset) {
  json m = json::parse(readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json"));
  m.erase("zones");
  m.erase("buildings");
  m.erase("orbits");
  m["zonesets"] = {zoneset};
  return m.dump();
}

/// A service with the example zones published and one approved flight of operator acme.
class Service : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratchPath("service-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    server_ = std::make_unique<ServiceProcess>(dir_, extraOptions());
    client_ = std::make_unique<HttpClient>(server_->port());
  }
  virtual std::vector<std::string> extraOptions() const { return {}; }
  HttpReply call(const std::string& method, const std::string& target, const char* token, const std::string& body = {},
                 const std::string& type = kJson) {
    std::vector<std::string> h;
    if (token) h.push_back(auth(token));
    if (!body.empty()) h.push_back(type);
    return client_->request(method, target, body, h);
  }
  std::string publishZones() {
    const HttpReply r = call("POST", "/v1/zonesets?name=zurich", TestTokens::kAuthority,
                             readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json"));
    EXPECT_EQ(r.status, 201) << r.body;
    return json::parse(r.body).at("id");
  }
  /// Submits the example mission for `token` and waits for its end; the approval's id.
  std::string approve(const char* token, const std::string& zoneset) {
    const HttpReply r = call("POST", "/v1/approvals", token, exampleMission(zoneset));
    EXPECT_EQ(r.status, 202) << r.body;
    const std::string id = json::parse(r.body).at("id");
    for (int i = 0; i < 600; ++i) {
      const json st = json::parse(call("GET", "/v1/approvals/" + id, token).body);
      if (st.at("status") != "queued" && st.at("status") != "running") break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return id;
  }
  std::string startFlight(const char* token, const std::string& approval) {
    const HttpReply r = call("POST", "/v1/flights", token, json{{"approval", approval}}.dump());
    EXPECT_EQ(r.status, 201) << r.body;
    return json::parse(r.body).at("id");
  }
  /// A fix k seconds after departure on the flight's route, shifted `off_m` metres north.
  json fixAt(const std::string& flight, int k, double off_m = 0.0, double pl_m = 0.5) {
    if (route_.is_null()) {  // the approved route, from the flight's approval report
      const json f = json::parse(call("GET", "/v1/flights/" + flight, TestTokens::kAcme).body);
      route_ = json::parse(call("GET", "/v1/approvals/" + f.at("approval").get<std::string>() + "/report.json", TestTokens::kAcme).body);
    }
    return test::fixAlongRoute(route_, k, off_m, pl_m);
  }
  std::string dir_;
  std::unique_ptr<ServiceProcess> server_;
  std::unique_ptr<HttpClient> client_;
  json route_;
};

TEST_F(Service, EveryApiRouteWithoutAValidTokenIs401AndHealthNeedsNone) {
  EXPECT_EQ(call("GET", "/healthz", nullptr).status, 200);
  EXPECT_EQ(call("GET", "/readyz", nullptr).status, 200);
  const std::vector<std::pair<std::string, std::string>> routes = {
      {"GET", "/v1/openapi.json"},     {"GET", "/v1/zonesets"},        {"POST", "/v1/zonesets?name=x"}, {"GET", "/v1/zonesets/zs-1"},
      {"PUT", "/v1/zonesets/zs-1"},    {"GET", "/v1/zonesets/zs-1/geojson"}, {"GET", "/v1/zones?lat=1&lon=1&time=2020-01-01T00:00:00Z"},
      {"GET", "/v1/approvals"},        {"POST", "/v1/approvals"},      {"GET", "/v1/approvals/ap-1"},   {"GET", "/v1/approvals/ap-1/report.json"},
      {"GET", "/v1/flights"},          {"POST", "/v1/flights"},        {"GET", "/v1/flights/fl-1"},     {"GET", "/v1/flights/fl-1/route"},
      {"POST", "/v1/flights/fl-1/fixes"}, {"GET", "/v1/flights/fl-1/events"}, {"GET", "/v1/events"},   {"GET", "/metrics"},
      {"GET", "/v1/orbits"},           {"PUT", "/v1/orbits/alm.txt"}};
  for (const auto& [method, target] : routes) {
    const HttpReply none = call(method, target, nullptr, method == "GET" ? "" : "{}");
    EXPECT_EQ(none.status, 401) << method << " " << target;
    EXPECT_EQ(none.header("www-authenticate"), "Bearer realm=\"skylane\"") << target;
    EXPECT_NE(json::parse(none.body).at("error").get<std::string>().find("Authorization"), std::string::npos);
    const HttpReply wrong = call(method, target, "Bearer not-a-token", method == "GET" ? "" : "{}");
    EXPECT_EQ(wrong.status, 401) << method << " " << target;
  }
  EXPECT_EQ(call("GET", "/metrics", TestTokens::kAcme).status, 403);
  EXPECT_EQ(call("GET", "/metrics", TestTokens::kAuthority).status, 200);
  const json api = json::parse(call("GET", "/v1/openapi.json", TestTokens::kAcme).body);
  EXPECT_EQ(api.at("openapi"), "3.0.3");
  for (const auto& [method, target] : routes) {  // the document describes every route
    const std::string path = target.substr(0, target.find('?'));
    bool described = false;
    for (const auto& [p, item] : api.at("paths").items()) {
      const std::string prefix = p.substr(0, p.find('{'));
      described = described || p == path || (p.find('{') != std::string::npos && path.rfind(prefix, 0) == 0);
    }
    EXPECT_TRUE(described) << path;
  }
}

TEST_F(Service, AnOperatorNeverSeesOrChangesAnothersApprovalsFlightsOrZoneSets) {
  const std::string zs = publishZones();
  const std::string ap = approve(TestTokens::kAcme, zs);
  const std::string fl = startFlight(TestTokens::kAcme, ap);
  const HttpReply own = call("POST", "/v1/zonesets?name=acme-fence", TestTokens::kAcme,
                             readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json"));
  ASSERT_EQ(own.status, 201) << own.body;
  const std::string private_zs = json::parse(own.body).at("id");
  // Every cross-operator read or write answers 404, as for an id that does not exist.
  for (const std::string& target : {"/v1/approvals/" + ap, "/v1/approvals/" + ap + "/report.json", "/v1/approvals/" + ap + "/route.geojson",
                                    "/v1/flights/" + fl, "/v1/flights/" + fl + "/route", "/v1/flights/" + fl + "/events",
                                    "/v1/zonesets/" + private_zs, "/v1/zonesets/" + private_zs + "/geojson"}) {
    EXPECT_EQ(call("GET", target, TestTokens::kOther).status, 404) << target;
  }
  EXPECT_EQ(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kOther, fixAt(fl, 1).dump(), kNdjson).status, 404);
  EXPECT_EQ(call("POST", "/v1/flights", TestTokens::kOther, json{{"approval", ap}}.dump()).status, 404);
  EXPECT_EQ(call("PUT", "/v1/zonesets/" + private_zs, TestTokens::kOther, readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json")).status, 404);
  // Nor do lists show them, nor does a mission of another operator's private set pass.
  EXPECT_EQ(json::parse(call("GET", "/v1/approvals", TestTokens::kOther).body).at("approvals").size(), 0u);
  EXPECT_EQ(json::parse(call("GET", "/v1/flights", TestTokens::kOther).body).at("flights").size(), 0u);
  EXPECT_EQ(json::parse(call("GET", "/v1/zonesets", TestTokens::kOther).body).at("zonesets").size(), 1u);  // the public one
  const HttpReply stolen = call("POST", "/v1/approvals", TestTokens::kOther, exampleMission(private_zs));
  EXPECT_EQ(stolen.status, 400);
  EXPECT_NE(stolen.body.find("$.zonesets[0]"), std::string::npos) << stolen.body;
  // Only the authority publishes or changes a public set; it submits no approvals.
  EXPECT_EQ(call("PUT", "/v1/zonesets/" + zs, TestTokens::kAcme, readFile(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json")).status, 403);
  EXPECT_EQ(call("POST", "/v1/approvals", TestTokens::kAuthority, exampleMission(zs)).status, 403);
  // The owner sees its own.
  EXPECT_EQ(call("GET", "/v1/flights/" + fl, TestTokens::kAcme).status, 200);
  EXPECT_EQ(json::parse(call("GET", "/v1/zonesets", TestTokens::kAcme).body).at("zonesets").size(), 2u);
}

TEST_F(Service, BadRequestsGetTheErrorContract) {
  const std::string zs = publishZones();
  const auto error = [](const HttpReply& r) { return json::parse(r.body).at("error").get<std::string>(); };
  // 400 naming the field, the value and what was expected.
  json m = json::parse(exampleMission(zs));
  m["zones"] = {"/etc/passwd"};
  HttpReply r = call("POST", "/v1/approvals", TestTokens::kAcme, m.dump());
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("$.zones"), std::string::npos) << r.body;
  m = json::parse(exampleMission(zs));
  m["k1"] = "wide";
  r = call("POST", "/v1/approvals", TestTokens::kAcme, m.dump());
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("k1"), std::string::npos) << r.body;
  EXPECT_EQ(error(r).find(dir_), std::string::npos) << "a message shows the server's folder: " << r.body;
  r = call("POST", "/v1/approvals", TestTokens::kAcme, "{\"name\": ");
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("the request body"), std::string::npos) << r.body;
  m = json::parse(exampleMission(zs));
  m["orbits"] = {"../../etc/passwd"};
  r = call("POST", "/v1/approvals", TestTokens::kAcme, m.dump());
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("$.orbits[0]"), std::string::npos) << r.body;
  r = call("POST", "/v1/zonesets?name=bad", TestTokens::kAuthority, R"({"type": "FeatureCollection", "features": [{"type": "Feature"}]})");
  EXPECT_EQ(r.status, 400) << r.body;
  r = call("GET", "/v1/zones?lat=95&lon=8&time=2020-01-01T00:00:00Z", TestTokens::kAcme);
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("lat"), std::string::npos);
  r = call("GET", "/v1/zones?bbox=8,47,7,48", TestTokens::kAcme);
  EXPECT_EQ(r.status, 400);
  EXPECT_NE(error(r).find("W,S,E,N"), std::string::npos);
  // 404, 405, 409, 415.
  EXPECT_EQ(call("GET", "/v1/nothing", TestTokens::kAcme).status, 404);
  r = call("DELETE", "/v1/approvals", TestTokens::kAcme);
  EXPECT_EQ(r.status, 405);
  EXPECT_EQ(r.header("allow"), "GET, POST");
  EXPECT_EQ(call("POST", "/v1/approvals", TestTokens::kAcme, exampleMission(zs), "Content-Type: text/plain").status, 415);
  EXPECT_EQ(call("POST", "/v1/approvals", TestTokens::kAcme, exampleMission(zs), "X-None: 1").status, 415);
  const std::string ap = json::parse(call("POST", "/v1/approvals", TestTokens::kAcme, exampleMission(zs)).body).at("id");
  r = call("GET", "/v1/approvals/" + ap + "/report.json", TestTokens::kAcme);
  EXPECT_TRUE(r.status == 409 || r.status == 200) << r.status;  // 409 while the approval runs
}

TEST_F(Service, AnOperatorsUploadedAlmanacServesItsMissionsAndNoOneElses) {
  const std::string zs = publishZones();
  const std::string almanac = readFile(test::dataPath("gnss/alm01jan2020.txt"));
  const std::string text = "Content-Type: text/plain";
  HttpReply r = call("PUT", "/v1/orbits/acme-alm.txt", TestTokens::kAcme, almanac, text);
  ASSERT_EQ(r.status, 201) << r.body;
  r = call("PUT", "/v1/orbits/broken.txt", TestTokens::kAcme, "******** Week 42 almanac for PRN-01 ********\nID: x\n", text);
  EXPECT_EQ(r.status, 400) << r.body;
  EXPECT_NE(r.body.find("broken.txt"), std::string::npos) << r.body;
  EXPECT_EQ(r.body.find(dir_), std::string::npos) << r.body;
  EXPECT_EQ(call("PUT", "/v1/orbits/..hidden", TestTokens::kAcme, almanac, text).status, 400);
  EXPECT_EQ(call("PUT", "/v1/orbits/a.txt", TestTokens::kAcme, almanac).status, 415);  // JSON is not an orbit file
  const json listed = json::parse(call("GET", "/v1/orbits", TestTokens::kAcme).body).at("orbits");
  EXPECT_TRUE(std::any_of(listed.begin(), listed.end(), [](const json& o) { return o["name"] == "acme-alm.txt" && o["from"] == "operator"; }));
  json m = json::parse(exampleMission(zs));
  m["orbits"] = {"acme-alm.txt"};
  r = call("POST", "/v1/approvals", TestTokens::kAcme, m.dump());
  ASSERT_EQ(r.status, 202) << r.body;
  EXPECT_EQ(call("POST", "/v1/approvals", TestTokens::kOther, m.dump()).status, 400);  // not its file
  const json other = json::parse(call("GET", "/v1/orbits", TestTokens::kOther).body).at("orbits");
  EXPECT_FALSE(std::any_of(other.begin(), other.end(), [](const json& o) { return o["name"] == "acme-alm.txt"; }));
}

TEST_F(Service, ZonesAreQueriedAtAPointAndTimeAndInABox) {
  const std::string zs = publishZones();
  const json all = json::parse(call("GET", "/v1/zonesets/" + zs + "/geojson", TestTokens::kAcme).body);
  ASSERT_EQ(all.at("features").size(), 5u);
  // Every zone's own point (a polygon's first vertex moved 1 mm inwards is not needed: a circle's
  // centre, a polygon's vertex average for these convex outlines) lies in that zone and the query
  // at its active time finds it; far away, none.
  int found = 0;
  for (const json& f : all.at("features")) {
    const json& g = f.at("geometry");
    double lat = 0, lon = 0;
    if (g.at("type") == "Point") {
      lon = g["coordinates"][0], lat = g["coordinates"][1];
    } else {
      const json& ring = g["coordinates"][0];
      for (std::size_t i = 0; i + 1 < ring.size(); ++i) lon += ring[i][0].get<double>(), lat += ring[i][1].get<double>();
      lon /= double(ring.size() - 1), lat /= double(ring.size() - 1);
    }
    const json& app = f["properties"]["applicability"];
    const std::string t = app.empty() || !app[0].contains("start") ? "2020-01-01T14:00:00Z" : app[0]["start"].get<std::string>();
    const json at = json::parse(call("GET", "/v1/zones?lat=" + std::to_string(lat) + "&lon=" + std::to_string(lon) + "&time=" + t,
                                     TestTokens::kAcme).body);
    for (const json& g2 : at.at("features")) found += g2["properties"]["identifier"] == f["properties"]["identifier"];
  }
  EXPECT_EQ(found, 5);
  EXPECT_EQ(json::parse(call("GET", "/v1/zones?lat=0&lon=0&time=2020-01-01T14:00:00Z", TestTokens::kAcme).body).at("features").size(), 0u);
  EXPECT_EQ(json::parse(call("GET", "/v1/zones?bbox=8.4,47.3,8.7,47.5", TestTokens::kAcme).body).at("features").size(), 5u);
  EXPECT_EQ(json::parse(call("GET", "/v1/zones?bbox=0,0,1,1", TestTokens::kAcme).body).at("features").size(), 0u);
}

/// Event lines without what names the input (the service's request lines, the CLI's file) and
/// the planner's wall-clock time. A rejected line names its flight in the service (the URL's).
json comparable(json e) {
  for (const char* k : {"line", "source", "report", "error", "planning_time_s"}) e.erase(k);
  if (e.at("event") == "rejected_input") e.erase("flight");
  return e;
}

TEST_F(Service, TrackingThroughTheServiceGivesTheEventsOfSkylaneTrack) {
  const std::string zs = publishZones();
  const std::string ap = approve(TestTokens::kAcme, zs);
  ASSERT_EQ(json::parse(call("GET", "/v1/approvals/" + ap, TestTokens::kAcme).body).at("status"), "approved");
  const std::string fl = startFlight(TestTokens::kAcme, ap);
  // Before any replan the flight's route is the approved one: the same boxes as the approval's
  // route.geojson (made from the report's map positions; the flight's from its lat/lon).
  const json approved = json::parse(call("GET", "/v1/approvals/" + ap + "/route.geojson", TestTokens::kAcme).body);
  const json current = json::parse(call("GET", "/v1/flights/" + fl + "/route", TestTokens::kAcme).body);
  ASSERT_EQ(current.at("features").size(), approved.at("features").size() - 0u) << current.dump();
  for (std::size_t i = 0; i < current["features"].size(); ++i) {
    const json &a = approved["features"][i], &b = current["features"][i];
    EXPECT_EQ(a["properties"]["kind"], b["properties"]["kind"]);
    if (a["geometry"]["type"] != "Polygon") continue;
    for (std::size_t v = 0; v < a["geometry"]["coordinates"][0].size(); ++v) {
      for (int c = 0; c < 2; ++c) {
        EXPECT_NEAR(a["geometry"]["coordinates"][0][v][c].get<double>(), b["geometry"]["coordinates"][0][v][c].get<double>(), 2e-8);
      }
    }
  }
  // On the route, then 40 m off it (a level-1 violation, held: a replan), then a bad line.
  std::string body;
  for (int k = 0; k < 30; ++k) body += fixAt(fl, k, k >= 12 && k < 20 ? 40.0 : 0.0).dump() + "\n";
  body += "{\"time\": 3}\n";
  const HttpReply r = call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, body, kNdjson);
  ASSERT_EQ(r.status, 200) << r.body;
  const json got = json::parse(r.body);
  EXPECT_EQ(got.at("accepted"), 30);
  EXPECT_EQ(got.at("rejected"), 1);
  // The same approval and fixes through `skylane track`, an independent run of the engine.
  const std::string fixes = dir_ + "/fixes.jsonl";
  std::ofstream(fixes) << body;
  const std::string report = dir_ + "/service.sqlite.files/approvals/" + ap + "/report.json";
  const test::CommandResult cli = test::runCommand(std::string(SKYLANE_BINARY) + " track --approval " + fl + "=" + report +
                                                   " --input " + fixes + " 2>/dev/null");
  std::vector<json> expected;
  std::istringstream lines(cli.out);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) expected.push_back(comparable(json::parse(line)));
  }
  std::vector<json> actual;
  for (const json& e : got.at("events")) {
    if (e.at("event") == "rejected_input") {
      EXPECT_EQ(e.at("flight"), fl);
    }
    actual.push_back(comparable(e));
  }
  ASSERT_EQ(actual.size(), expected.size()) << cli.out;
  for (std::size_t i = 0; i < actual.size(); ++i) EXPECT_EQ(actual[i], expected[i]) << i;
  const auto count = [&](const char* type) {
    return std::count_if(actual.begin(), actual.end(), [&](const json& e) { return e.at("event") == type; });
  };
  EXPECT_GE(count("violation"), 1);
  EXPECT_GE(count("replan"), 1);
  // The flight's route is now the last replan's, and the list shows its last fix.
  const json after = json::parse(call("GET", "/v1/flights/" + fl + "/route", TestTokens::kAcme).body);
  EXPECT_EQ(after["features"][0]["properties"]["route_version"], count("replan"));
  EXPECT_GT(std::count_if(after["features"].begin(), after["features"].end(), [](const json& f) { return f["properties"]["kind"] == "corridor"; }), 0);
  const json listed = json::parse(call("GET", "/v1/flights", TestTokens::kAcme).body).at("flights").at(0);
  json last_fix;
  for (const json& e : got.at("events")) {
    if (e.at("event") == "fix") last_fix = e;
  }
  EXPECT_EQ(listed.at("last_fix"), last_fix);
  EXPECT_EQ(count("rejected_input"), 1);
}

TEST_F(Service, EventStreamsDeliverLiveAndResumeAfterLastEventId) {
  const std::string zs = publishZones();
  const std::string fl = startFlight(TestTokens::kAcme, approve(TestTokens::kAcme, zs));
  HttpClient stream(server_->port());
  stream.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme)});
  ASSERT_TRUE(stream.waitFor("retry: 1000", 2000)) << stream.streamed();
  EXPECT_EQ(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, fixAt(fl, 1).dump() + "\n" + fixAt(fl, 2).dump(), kNdjson).status, 200);
  ASSERT_TRUE(stream.waitFor("id: 2\n", 2000)) << stream.streamed();
  EXPECT_NE(stream.streamed().find("event: fix\ndata: {"), std::string::npos);
  // A stream of all the operator's flights, resumed after event 1: event 2 and on, not 1.
  HttpClient resumed(server_->port());
  resumed.openStream("/v1/events", {auth(TestTokens::kAcme), "Last-Event-ID: 1"});
  ASSERT_TRUE(resumed.waitFor("id: 2\n", 2000)) << resumed.streamed();
  EXPECT_EQ(resumed.streamed().find("id: 1\n"), std::string::npos);
  EXPECT_EQ(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, fixAt(fl, 3).dump(), kNdjson).status, 200);
  EXPECT_TRUE(resumed.waitFor("id: 3\n", 2000)) << resumed.streamed();
  // Another operator's stream of all its flights sees none of these.
  HttpClient other(server_->port());
  other.openStream("/v1/events", {auth(TestTokens::kOther), "Last-Event-ID: 0"});
  other.readFor(300);
  EXPECT_EQ(other.streamed().find("id: "), std::string::npos) << other.streamed();
}

class ServiceLimits : public Service {
 protected:
  std::vector<std::string> extraOptions() const override {
    return {"--rate", "5", "--burst", "5", "--max-body", "100000", "--request-timeout", "1", "--approval-queue", "1"};
  }
};

TEST_F(ServiceLimits, RateBodyHeaderAndSlowClientLimitsHoldAndTheServiceGoesOn) {
  // Over the token's rate: 429 with Retry-After; another token is not slowed.
  int refused = 0;
  for (int i = 0; i < 8; ++i) {
    const HttpReply r = call("GET", "/v1/zonesets", TestTokens::kAcme);
    if (r.status == 429) {
      ++refused;
      EXPECT_FALSE(r.header("retry-after").empty());
    }
  }
  EXPECT_GE(refused, 2);
  EXPECT_EQ(call("GET", "/v1/zonesets", TestTokens::kOther).status, 200);
  // An oversized body: 413 before it is read; huge headers: 431; garbage: 400.
  HttpClient raw(server_->port());
  EXPECT_NE(raw.raw("POST /v1/zonesets?name=x HTTP/1.1\r\nHost: a\r\nContent-Length: 200000\r\n\r\n").find(" 413 "), std::string::npos);
  EXPECT_NE(raw.raw("GET / HTTP/1.1\r\nX-Big: " + std::string(40000, 'a') + "\r\n\r\n").find(" 431 "), std::string::npos);
  EXPECT_NE(raw.raw("\x01\x02 nonsense\r\n\r\n").find(" 400 "), std::string::npos);
  // A client that stops half-way through its request is cut off after the request timeout.
  const auto t0 = std::chrono::steady_clock::now();
  raw.raw("POST /v1/zonesets HTTP/1.1\r\nHost: a\r\nContent-Length: 50\r\n\r\n{", 5000);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(waited, 4.0);
  // Many connections at once, and the service still answers.
  std::vector<std::unique_ptr<HttpClient>> many;
  for (int i = 0; i < 200; ++i) many.push_back(std::make_unique<HttpClient>(server_->port()));
  for (auto& c : many) c->openStream("/healthz", {});
  EXPECT_EQ(call("GET", "/healthz", nullptr).status, 200);
}

TEST_F(ServiceLimits, AFullApprovalQueueAnswers429WithRetryAfter) {
  std::this_thread::sleep_for(std::chrono::seconds(1));  // the rate bucket refilled
  const std::string zs = publishZones();
  int accepted = 0, full = 0;
  for (int i = 0; i < 4; ++i) {
    const HttpReply r = call("POST", "/v1/approvals", TestTokens::kOther, exampleMission(zs));
    accepted += r.status == 202;
    if (r.status == 429 && r.body.find("queue") != std::string::npos) {
      ++full;
      EXPECT_EQ(r.header("retry-after"), "5");
    }
  }
  EXPECT_GE(accepted, 1);
  EXPECT_GE(full, 1);
}

TEST_F(Service, KilledMidStreamOfFixesItLosesNoAcknowledgedFixAndDoublesNone) {
  const std::string zs = publishZones();
  const std::string fl = startFlight(TestTokens::kAcme, approve(TestTokens::kAcme, zs));
  std::vector<json> fixes;
  for (int k = 0; k < 150; ++k) fixes.push_back(fixAt(fl, k));
  std::atomic<int> acknowledged{0};
  std::thread poster([&] {
    HttpClient c(server_->port());
    try {
      for (const json& f : fixes) {
        if (c.request("POST", "/v1/flights/" + fl + "/fixes", f.dump(), {auth(TestTokens::kAcme), kNdjson}).status != 200) break;
        ++acknowledged;
      }
    } catch (const std::exception&) {  // the server went away mid-request
    }
  });
  while (acknowledged < 60) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(server_->kill(SIGKILL), 128 + SIGKILL);
  poster.join();
  const int acked = acknowledged;
  server_->start();
  client_ = std::make_unique<HttpClient>(server_->port());
  const json st = json::parse(call("GET", "/v1/flights/" + fl, TestTokens::kAcme).body).at("state");
  const int kept = st.at("fixes");
  // Every acknowledged fix is kept; at most the one in flight at the kill was kept unacknowledged.
  EXPECT_GE(kept, acked);
  EXPECT_LE(kept, acked + 1);
  // The event log holds exactly one fix event per kept fix; posting the rest goes on from there.
  HttpClient log(server_->port());
  log.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme), "Last-Event-ID: 0"});
  log.readFor(500);
  std::size_t fix_events = 0;
  for (std::size_t at = 0; (at = log.streamed().find("event: fix\n", at)) != std::string::npos; ++at) ++fix_events;
  EXPECT_EQ(fix_events, static_cast<std::size_t>(kept));
  std::string rest;
  for (std::size_t k = static_cast<std::size_t>(kept); k < fixes.size(); ++k) rest += fixes[k].dump() + "\n";
  const json r = json::parse(call("POST", "/v1/flights/" + fl + "/fixes", TestTokens::kAcme, rest, kNdjson).body);
  EXPECT_EQ(r.at("accepted"), static_cast<int>(fixes.size()) - kept);
  EXPECT_EQ(json::parse(call("GET", "/v1/flights/" + fl, TestTokens::kAcme).body)["state"]["fixes"], 150);
}

}  // namespace
}  // namespace skylane

namespace skylane {
namespace {

/// A free UDP port on the loopback (bound and released; the service binds it next).
void sendUdp(int port, const std::string& datagram) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::sendto(fd, datagram.data(), datagram.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::close(fd);
}

class ServiceUdpInput : public Service {
 protected:
  std::vector<std::string> extraOptions() const override {
    udp_port_ = freeUdpPort();
    return {"--input", "jsonl:udp://127.0.0.1:" + std::to_string(udp_port_)};
  }
  mutable int udp_port_ = 0;
};

TEST_F(ServiceUdpInput, FixesFromAUdpInputAreJudgedByTheSameEngineAndStream) {
  const std::string zs = publishZones();
  const std::string fl = startFlight(TestTokens::kAcme, approve(TestTokens::kAcme, zs));
  HttpClient stream(server_->port());
  stream.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme)});
  ASSERT_TRUE(stream.waitFor("retry: 1000", 2000));
  json f1 = fixAt(fl, 1), f2 = fixAt(fl, 2, 40.0);
  f1["flight"] = fl, f2["flight"] = fl;
  sendUdp(udp_port_, f1.dump() + "\n" + f2.dump() + "\n");
  sendUdp(udp_port_, R"({"flight": "fl-nobody", "time": "2020-01-01T14:00:03Z", "lat": 47, "lon": 8, "h_ell_m": 500, "hpl_m": 1, "vpl_m": 1})");
  ASSERT_TRUE(stream.waitFor("event: violation", 3000)) << stream.streamed();
  EXPECT_TRUE(stream.waitFor("id: 3\n", 3000)) << stream.streamed();  // fix, violation, fix
  const json st = json::parse(call("GET", "/v1/flights/" + fl, TestTokens::kAcme).body).at("state");
  EXPECT_EQ(st.at("fixes"), 2);
  // The record for a flight the service does not track is a rejected input naming it.
  HttpClient all(server_->port());
  all.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme), "Last-Event-ID: 0"});
  all.readFor(300);
  EXPECT_EQ(all.streamed().find("fl-nobody"), std::string::npos);  // not this flight's
  const HttpReply metrics = call("GET", "/metrics", TestTokens::kAuthority);
  EXPECT_NE(metrics.body.find("skylane_inputs_rejected_total 1\n"), std::string::npos) << metrics.body;
}

/// A counter's value in the /metrics text (-1 when absent).
long long metricValue(const std::string& text, const std::string& name) {
  const auto at = text.find("\n" + name + " ");
  return at == std::string::npos ? -1 : std::stoll(text.substr(at + name.size() + 2));
}

TEST_F(ServiceUdpInput, KernelDropsOnAFloodedUdpInputAreEventsAndAMetric) {
  // GIVEN the service restarted with a UDP input whose receive buffer is the smallest allowed
  const std::string fl = startFlight(TestTokens::kAcme, approve(TestTokens::kAcme, publishZones()));
  std::vector<std::string> lines;
  constexpr int kSent = 3000;
  for (int k = 1; k <= kSent; ++k) {
    json f = fixAt(fl, k);
    f["flight"] = fl;
    lines.push_back(f.dump() + "\n");
  }
  ASSERT_EQ(server_->kill(SIGTERM), 0);
  const int port = freeUdpPort();
  server_->start({"--input", "jsonl:udp://127.0.0.1:" + std::to_string(port), "--udp-buffer", "1024"});
  client_ = std::make_unique<HttpClient>(server_->port());
  // WHEN 3,000 fixes arrive flat out
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (const std::string& l : lines) ::sendto(fd, l.data(), l.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::close(fd);
  // THEN every datagram is accepted, rejected or counted dropped, and the drops are a metric
  long long accepted = 0, rejected = 0, dropped = 0;
  for (int i = 0; i < 100 && accepted + rejected + dropped < kSent; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const std::string m = call("GET", "/metrics", TestTokens::kAuthority).body;
    accepted = metricValue(m, "skylane_fixes_accepted_total");
    rejected = metricValue(m, "skylane_inputs_rejected_total");
    dropped = metricValue(m, "skylane_input_datagrams_dropped_total");
  }
  EXPECT_GT(dropped, 0);
  EXPECT_EQ(accepted + rejected + dropped, kSent) << accepted << " accepted, " << rejected << " rejected, " << dropped << " dropped";
  std::printf("service UDP flood: %d sent, %lld accepted, %lld rejected, %lld dropped by the kernel\n", kSent, accepted, rejected,
              dropped);
}

}  // namespace
}  // namespace skylane

namespace skylane {
namespace {

TEST(ServiceStart, ADamagedDatabaseOrTokensFileIsAClearErrorExit2) {
  const std::filesystem::path dir = test::scratchPath("service-start");
  std::filesystem::create_directories(dir);
  const std::string tokens = TestTokens::write(dir);
  std::ofstream(dir / "garbage.sqlite") << std::string(4096, '\x5a');
  const std::string bin = SKYLANE_BINARY;
  test::CommandResult r = test::runCommand(bin + " serve --db " + (dir / "garbage.sqlite").string() + " --tokens " + tokens +
                                           " --port 0 --web none 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("garbage.sqlite"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not a database"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  std::ofstream(dir / "empty_tokens.json") << R"({"tokens": [{"sha256": "abc", "operator": "x"}]})";
  r = test::runCommand(bin + " serve --db " + (dir / "ok.sqlite").string() + " --tokens " + (dir / "empty_tokens.json").string() +
                       " --port 0 --web none 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("$.tokens[0].sha256"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("64 lower-case hex"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace skylane

namespace skylane {
namespace {

TEST_F(ServiceUdpInput, AMavlinkLinkFromAnIndependentVehicleFeedsItsFlight) {
  // GIVEN a tracked flight, and the service restarted with a MAVLink input for it on a UDP port
  const std::string zs = publishZones();
  const std::string ap = approve(TestTokens::kAcme, zs);
  const std::string fl = startFlight(TestTokens::kAcme, ap);
  ASSERT_EQ(server_->kill(SIGTERM), 0);
  const int port = freeUdpPort();
  server_->start({"--input", "mavlink:udp://127.0.0.1:" + std::to_string(port) + "#" + fl});
  client_ = std::make_unique<HttpClient>(server_->port());
  // WHEN a vehicle written on node-mavlink flies the approved route for 30 s at 5 Hz (150
  // GPS_RAW_INT frames, h_acc 150 mm, v_acc 200 mm) with junk bytes and a corrupted frame
  const std::string report = dir_ + "/service.sqlite.files/approvals/" + ap + "/report.json";
  const test::CommandResult v = test::runCommand("node " + std::string(SKYLANE_TEST_DATA) + "/../link/js/vehicle.mjs --report " + report +
                                                 " --port " + std::to_string(port) + " --seconds 30 --garbage 2>&1 || echo vehicle-failed");
  ASSERT_EQ(v.out.find("vehicle-failed"), std::string::npos) << v.out;
  json st;
  for (int i = 0; i < 100; ++i) {
    st = json::parse(call("GET", "/v1/flights/" + fl, TestTokens::kAcme).body);
    if (st["state"]["fixes"] >= 150) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  // THEN every good frame is a fix of that flight, inside its corridor, with the PLs of the
  // documented accuracy rule, and the bad bytes are rejected inputs naming the flight
  EXPECT_EQ(st["state"]["fixes"], 150) << st.dump();
  ASSERT_TRUE(st.contains("last_fix")) << st.dump();
  EXPECT_EQ(st["last_fix"]["pl_source"], "mavlink_accuracy");
  EXPECT_EQ(st["last_fix"]["verdict"], "inside") << st["last_fix"].dump();
  EXPECT_NEAR(st["last_fix"]["hpl_m"].get<double>(), std::sqrt(-2.0 * std::log(2e-9)) * 0.15, 2e-3);
  HttpClient log(server_->port());
  log.openStream("/v1/flights/" + fl + "/events", {auth(TestTokens::kAcme), "Last-Event-ID: 0"});
  log.readFor(500);
  EXPECT_NE(log.streamed().find("event: rejected_input"), std::string::npos);
  EXPECT_NE(log.streamed().find("bad checksum"), std::string::npos);
}

}  // namespace
}  // namespace skylane
