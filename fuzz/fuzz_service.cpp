/// \file
/// \brief libFuzzer target for the service's routes (service/service_impl.hpp): every request a
/// client can make, after the HTTP parser, goes through ServiceImpl::handle. One service is
/// started for the whole run (in LLVMFuzzerInitialize) in a scratch folder, with the example zones published, the example
/// mission approved (by the real `skylane approve`) and one flight tracked.
///
/// The input is a request: a first line "METHOD TARGET", header lines "name: value" up to an
/// empty line, then the body. "{ZS}", "{AP}" and "{FL}" in the target or body become the ids of
/// the zone set, the approval and the flight; a request with no Authorization header gets the
/// operator's token when its first byte is even (so most inputs pass the authentication).
///
/// Checks: handle() returns (no exception escapes a route: on the wire it would be a 500), the
/// status is one the API documents, every JSON answer parses, and an error answer is an object
/// with a one-line "error" string.

#include "fuzz/fuzz_common.hpp"
#include "maps/file_digest.hpp"
#include "service/service_impl.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

namespace {

using namespace skylane;
using nlohmann::json;
namespace fs = std::filesystem;

const std::string kOperator = "Bearer fuzz-operator";
const std::string kAuthority = "Bearer fuzz-authority";

struct Fixture {
  fs::path dir;
  std::unique_ptr<service::ServiceImpl> impl;
  std::string zs, ap, fl;
  ~Fixture() {
    impl.reset();
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

std::string slurp(const std::string& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

service::HttpRequest request(const std::string& method, const std::string& path, const std::string& token, const std::string& body,
                             const std::string& type = "application/json") {
  service::HttpRequest r;
  r.method = method;
  r.target = r.path = path.substr(0, path.find('?'));
  if (path.find('?') != std::string::npos) r.query["name"] = "fuzz";
  r.headers["authorization"] = token;
  r.headers["content-type"] = type;
  r.body = body;
  return r;
}

std::unique_ptr<Fixture> makeFixture() {
  auto px = std::make_unique<Fixture>();
  Fixture& x = *px;
  x.dir = fs::temp_directory_path() / ("skylane-fuzz-service-" + std::to_string(getpid()));
  const fs::path& dir = x.dir;
  fs::create_directories(dir / "orbits");
  fs::copy_file(std::string(SKYLANE_SOURCE_DIR) + "/tests/data/gnss/alm01jan2020.txt", dir / "orbits/alm.txt", fs::copy_options::overwrite_existing);
  service::ServeOptions o;
  o.db = (dir / "s.sqlite").string();
  o.tokens = (dir / "tokens.json").string();
  o.orbits_dir = (dir / "orbits").string();
  o.program = SKYLANE_BINARY;
  o.port = 0;
  o.rate_per_s = 1e9, o.rate_burst = 1e9;
  std::ofstream(o.tokens) << R"({"tokens": [{"sha256": ")" << maps::sha256Hex("fuzz-authority") << R"(", "role": "authority"},)"
                          << R"({"sha256": ")" << maps::sha256Hex("fuzz-operator") << R"(", "operator": "acme"}]})";
  x.impl = std::make_unique<service::ServiceImpl>(o, [](const std::string&) {});
  auto& s = *x.impl;
  x.zs = json::parse(s.handle(request("POST", "/v1/zonesets?name", kAuthority, slurp(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json"))).body)["id"];
  json m = json::parse(slurp(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json"));
  m.erase("zones"), m.erase("buildings"), m.erase("orbits");
  m["zonesets"] = {x.zs};
  x.ap = json::parse(s.handle(request("POST", "/v1/approvals", kOperator, m.dump())).body)["id"];
  while (s.approvals.at(x.ap).row.status == "queued" || s.approvals.at(x.ap).row.status == "running") {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    s.server->poll();  // the worker's result comes in through the server's queue
  }
  x.fl = json::parse(s.handle(request("POST", "/v1/flights", kOperator, json{{"approval", x.ap}}.dump())).body).value("id", "");
  SKYLANE_FUZZ_CHECK(!x.fl.empty(), "the fixture's flight could not be started (approval " + s.approvals.at(x.ap).row.status + ")");
  return px;
}

/// The fixture, built on the first call and removed (service stopped, scratch folder deleted) by
/// the static's destructor when the process exits. LLVMFuzzerInitialize makes that first call,
/// so its cost (a real `skylane approve` run, a second or more on a loaded machine) is paid
/// before libFuzzer starts its per-input timer; a driver without the hook builds it lazily.
Fixture& fixture() {
  static const std::unique_ptr<Fixture> f = makeFixture();
  return *f;
}

std::string substituted(std::string s, const Fixture& f) {
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"{ZS}", f.zs}, {"{AP}", f.ap}, {"{FL}", f.fl}}) {
    for (std::size_t at; (at = s.find(key)) != std::string::npos;) s.replace(at, key.size(), value);
  }
  return s;
}

/// The fuzz input as a request (the file comment's form).
service::HttpRequest parseInput(const std::string& text, const Fixture& f) {
  service::HttpRequest r;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  const std::size_t sp = line.find(' ');
  r.method = line.substr(0, sp);
  r.target = substituted(sp == std::string::npos ? "/" : line.substr(sp + 1), f);
  const std::size_t q = r.target.find('?');
  r.path = r.target.substr(0, q);
  if (q != std::string::npos) {
    std::istringstream params(r.target.substr(q + 1));
    for (std::string kv; std::getline(params, kv, '&');) r.query[kv.substr(0, kv.find('='))] = kv.find('=') == std::string::npos ? "" : kv.substr(kv.find('=') + 1);
  }
  while (std::getline(in, line) && !line.empty()) {
    const std::size_t colon = line.find(':');
    if (colon != std::string::npos) r.headers[line.substr(0, colon)] = line.substr(std::min(line.size(), colon + 2));
  }
  std::ostringstream rest;
  rest << in.rdbuf();
  r.body = substituted(rest.str(), f);
  if (!r.headers.count("authorization") && !text.empty() && static_cast<unsigned char>(text[0]) % 2 == 0) r.headers["authorization"] = kOperator;
  return r;
}

}  // namespace

/// libFuzzer's set-up hook (called once, before any input and before the -timeout alarm is
/// armed): builds the fixture, which would otherwise be charged to the first input, on a busy
/// machine more than the timeout, reported as a "timeout" on the empty input.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  fixture();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Fixture& f = fixture();
  const service::HttpRequest r = parseInput(std::string(reinterpret_cast<const char*>(data), size), f);
  const service::HttpResponse res = f.impl->handle(r);
  static const std::set<int> kStatuses = {200, 201, 202, 400, 401, 403, 404, 405, 409, 413, 415, 429};
  SKYLANE_FUZZ_CHECK(kStatuses.count(res.status), std::to_string(res.status) + " " + res.body);
  if (res.stream) res.stream->close();
  if (res.content_type.rfind("application/", 0) == 0 && res.content_type.find("json") != std::string::npos && !res.stream) {
    const json j = json::parse(res.body, nullptr, false);
    SKYLANE_FUZZ_CHECK(!j.is_discarded(), "an answer that is not JSON: " + res.body.substr(0, 200));
    if (res.status >= 400) {
      SKYLANE_FUZZ_CHECK(j.is_object() && j.contains("error") && j["error"].is_string(), res.body.substr(0, 200));
      SKYLANE_FUZZ_CHECK(j["error"].get<std::string>().find('\n') == std::string::npos, "an error of more than one line: " + res.body.substr(0, 200));
    }
  }
  f.impl->server->poll();
  return 0;
}
