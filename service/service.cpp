#include "service/service.hpp"

#include "maps/atomic_file.hpp"
#include "maps/text_file.hpp"
#include "service/service_impl.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

namespace skylane::service {

namespace fs = std::filesystem;

// --- helpers of the route files --------------------------------------------------------------

std::string newId(const char* prefix) {
  static std::random_device rd;
  static std::mt19937_64 gen(rd());
  std::ostringstream s;
  s << prefix << std::hex;
  s.width(16);
  s.fill('0');
  s << gen();
  return s.str();
}

std::string nowUtc() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[96];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour,
                tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

std::optional<HttpResponse> requireContentType(const HttpRequest& r, std::initializer_list<const char*> types) {
  std::string type = r.header("content-type");
  type = type.substr(0, type.find(';'));
  while (!type.empty() && type.back() == ' ') type.pop_back();
  for (const char* t : types) {
    if (type == t) return std::nullopt;
  }
  std::string list;
  for (const char* t : types) list += (list.empty() ? "" : ", ") + std::string(t);
  return errorResponse(415, "Content-Type: " + (type.empty() ? std::string("none") : "\"" + type + "\"") + " is not accepted here; expected " + list);
}

HttpResponse methodNotAllowed(const std::string& allow) {
  HttpResponse r = errorResponse(405, "method not allowed here; allowed: " + allow);
  r.headers.emplace_back("Allow", allow);
  return r;
}

HttpResponse notFound(const std::string& what) { return errorResponse(404, "no such " + what); }

HttpResponse jsonBody(int status, const nlohmann::json& j) {
  return jsonResponse(status, j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

void writeFileAtomically(const fs::path& p, const std::string& text) {
  maps::AtomicFile f(p.string(), "the service folder");
  f.stream() << text;
  f.commit();
}

HttpResponse fileResponse(const fs::path& p, const std::string& content_type) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return notFound("file " + p.filename().string());
  HttpResponse r;
  r.content_type = content_type;
  r.body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return r;
}

// --- start and restart -----------------------------------------------------------------------

namespace {

fs::path filesFolder(const std::string& db) {
  // Absolute: missions written into an approval's folder name the zone set files by path.
  fs::path p = fs::absolute(fs::path(db));
  p += ".files";
  return p;
}

}  // namespace

ServiceImpl::ServiceImpl(ServeOptions o, Service::Log l)
    : options(std::move(o)), log(std::move(l)), files(filesFolder(options.db)), tokens(TokenTable::load(options.tokens)),
      limiter(options.rate_per_s, options.rate_burst) {
  std::error_code ec;
  fs::create_directories(files / "zonesets", ec);
  if (!ec) fs::create_directories(files / "approvals", ec);
  if (ec) throw std::runtime_error("--db " + options.db + ": cannot make the folder " + files.string() + ": " + ec.message());
  store = std::make_unique<ServiceStore>(options.db);
  auto track_store = std::make_unique<planner::TrackStore>(options.db);
  const planner::TrackStore& ts = *track_store;
  session = std::make_unique<planner::TrackingSession>(planner::TrackerOptions{}, std::move(track_store), 1 << 30,
                                                       [this](const std::string& m) { log(m); });
  hub = std::make_unique<EventHub>(ts);
  session->addSink(*hub);
  hub->observers.push_back([this](const HubEvent& e) {
    ++metrics.events;
    if (e.type == "fix") {
      ++metrics.fixes_accepted;
      last_fix[e.flight] = e.line;
    }
    if (e.type == "rejected_input") ++metrics.inputs_rejected;
  });
  server = std::make_unique<HttpServer>(options.host, options.port, [this](const HttpRequest& r) { return handle(r); }, options.limits);
  pool = std::make_unique<ApprovalPool>(
      options.program, options.approval_workers, options.approval_queue,
      [this](const std::string& id, const std::string& line) {
        server->post([this, id, line] {
          const auto it = approvals.find(id);
          if (it == approvals.end()) return;
          it->second.progress.push_back(line);
          if (it->second.row.status == "queued") {
            it->second.row.status = "running";
            store->putApproval(it->second.row);
          }
        });
      },
      [this](const std::string& id, const ApprovalOutcome& outcome) { server->post([this, id, outcome] { approvalDone(id, outcome); }); });
  if (!options.nats_url.empty()) startNats();
  restore();
  addGauges();
  server->every(std::chrono::seconds(15), [this] { hub->keepAlive(); });
}

ServiceImpl::~ServiceImpl() {
  stopping = true;
  nats.reset();  // its reader posts to the server
  for (auto& in : inputs) {
    if (in->thread.joinable()) in->thread.join();
  }
  pool.reset();  // the workers stop before what their callbacks touch goes
}

void ServiceImpl::startInput(Input& in) {
  in.thread = std::thread([this, &in] {
    // A UDP input's kernel drops go to the service's thread once a second at most while
    // datagrams flow, and whenever the input is quiet (as in TrackingSession::run).
    std::uint64_t posted_drops = 0;
    auto last_drops = std::chrono::steady_clock::now();
    const auto postDrops = [&](bool now) {
      const auto dropped = in.source->droppedDatagrams();
      const auto wall = std::chrono::steady_clock::now();
      if (!dropped || *dropped <= posted_drops || (!now && wall - last_drops < std::chrono::seconds(1))) return;
      last_drops = wall;
      server->post([this, name = in.source->name(), total = *dropped, step = *dropped - posted_drops] {
        metrics.datagrams_dropped += step;
        session->reportDropped(name, total);
        session->commit();
      });
      posted_drops = *dropped;
    };
    while (!stopping) {
      planner::SourceRecord r = in.source->next(250);
      postDrops(r.kind != planner::SourceRecord::Kind::kFix && r.kind != planner::SourceRecord::Kind::kBad);
      if (r.kind == planner::SourceRecord::Kind::kEnd) break;
      if (r.kind == planner::SourceRecord::Kind::kIdle) continue;
      server->post([this, r = std::move(r), flight = in.flight] { takeRecord(r, flight); });
    }
    const std::string name = in.source->name();
    server->post([this, name] { log("input " + name + " ended"); });
  });
}

void ServiceImpl::takeRecord(const planner::SourceRecord& r, const std::string& input_flight) {
  if (r.kind == planner::SourceRecord::Kind::kBad) {
    session->reject(r.where, r.line, r.error, r.flight.empty() ? input_flight : r.flight);
  } else {
    planner::TrackFix fix = r.fix;
    if (!input_flight.empty()) fix.flight = input_flight;
    if (fix.flight.empty() || !flights.count(fix.flight)) {
      session->reject(fix.source, fix.line, "no flight \"" + fix.flight.substr(0, 64) + "\" is tracked by this service", fix.flight);
    } else {
      session->submit(fix);
    }
  }
  session->commit();
}

void ServiceImpl::restore() {
  for (ZoneSet& z : store->zoneSets()) zonesets[z.id] = {std::move(z), {}};
  for (ApprovalRow& a : store->approvals()) {
    ApprovalState& st = approvals[a.id];
    st.row = std::move(a);
    st.submitted = std::chrono::steady_clock::now();
    // An approval the last run did not finish is run again.
    if (st.row.status == "queued" || st.row.status == "running") queueApproval(st);
  }
  for (FlightRow& f : store->flights()) flights[f.id] = std::move(f);
  last_fix = session->store()->lastEventOfEachFlight("fix");
  session->resumeFlights();
  log("serving " + std::to_string(zonesets.size()) + " zone sets, " + std::to_string(approvals.size()) + " approvals, " +
      std::to_string(flights.size()) + " flights from " + options.db);
}

void ServiceImpl::addGauges() {
  metrics.gauges["skylane_approval_queue_depth"] = {"Approvals waiting for a worker.", [this] { return double(pool->waiting()); }};
  metrics.gauges["skylane_approvals_running"] = {"Approvals being computed.", [this] { return double(pool->running()); }};
  metrics.gauges["skylane_flights_tracked"] = {"Flights the tracking engine holds (with --nats: the flights started here).", [this] {
    return double(nats ? flights.size() : session->tracker().flights().size());
  }};
  metrics.gauges["skylane_event_streams"] = {"Open event streams.", [this] { return double(hub->streams()); }};
  metrics.gauges["skylane_http_connections"] = {"Open HTTP connections.", [this] { return double(server->connections()); }};
}

// --- dispatch --------------------------------------------------------------------------------

namespace {

Segments split(const std::string& path) {
  Segments out;
  std::size_t i = 0;
  while (i < path.size()) {
    const std::size_t j = path.find('/', i);
    const std::string part = path.substr(i, j == std::string::npos ? std::string::npos : j - i);
    if (!part.empty()) out.push_back(part);
    if (j == std::string::npos) break;
    i = j + 1;
  }
  return out;
}

HttpResponse unauthorised(const std::string& why) {
  HttpResponse r = errorResponse(401, why);
  r.headers.emplace_back("WWW-Authenticate", "Bearer realm=\"skylane\"");
  return r;
}

}  // namespace

HttpResponse ServiceImpl::handle(const HttpRequest& r) {
  ++metrics.requests;
  HttpResponse res = route(r);
  ++metrics.responses[res.status];
  return res;
}

HttpResponse ServiceImpl::readiness() const {
  if (!server || !pool) return errorResponse(503, "starting");
  return jsonBody(200, {{"status", "ready"}, {"flights", flights.size()}, {"approval_queue", pool->waiting()}});
}

HttpResponse ServiceImpl::route(const HttpRequest& r) {
  if (r.path == "/healthz") return jsonBody(200, {{"status", "ok"}});
  if (r.path == "/readyz") return readiness();
  const bool api = r.path.rfind("/v1/", 0) == 0 || r.path == "/v1" || r.path == "/metrics";
  if (!api) return serveStatic(r);
  const std::string auth = r.header("authorization");
  if (auth.empty()) return unauthorised("this route needs an Authorization: Bearer <token> header");
  const std::optional<Principal> who = tokens.find(auth);
  if (!who) return unauthorised("the bearer token is not known");
  double retry_s = 0.0;
  if (!limiter.allow(who->key, std::chrono::steady_clock::now(), retry_s)) {
    ++metrics.rate_limited;
    HttpResponse res = errorResponse(429, "too many requests for this token (limit " + std::to_string(int(options.rate_per_s)) + "/s)");
    res.headers.emplace_back("Retry-After", std::to_string(static_cast<int>(std::ceil(retry_s))));
    return res;
  }
  if (r.path == "/metrics") {
    if (!who->authority) return errorResponse(403, "/metrics is for the authority's token");
    HttpResponse res;
    res.content_type = "text/plain; version=0.0.4";
    res.body = metrics.text();
    return res;
  }
  return routeV1(r, *who, split(r.path));
}

HttpResponse ServiceImpl::routeV1(const HttpRequest& r, const Principal& who, const Segments& s) {
  if (s.size() < 2) return notFound("route " + r.path);
  const std::string& what = s[1];
  if (what == "openapi.json" && s.size() == 2) {
    if (r.method != "GET") return methodNotAllowed("GET");
    return jsonResponse(200, openApiDocument());
  }
  if (what == "zonesets") return zoneSets(r, who, s);
  if (what == "zones" && s.size() == 2) {
    if (r.method != "GET") return methodNotAllowed("GET");
    return zonesQuery(r, who);
  }
  if (what == "approvals") return approvalsRoute(r, who, s);
  if (what == "orbits") return orbitsRoute(r, who, s);
  if (what == "flights") return flightsRoute(r, who, s);
  if (what == "events" && s.size() == 2) {
    if (r.method != "GET") return methodNotAllowed("GET");
    return eventStream(r, who, {});
  }
  return notFound("route " + r.path);
}

HttpResponse ServiceImpl::serveStatic(const HttpRequest& r) const {
  if (r.method != "GET" && r.method != "HEAD") return methodNotAllowed("GET, HEAD");
  if (options.web_dir.empty()) return notFound("page (this service was started without the web map)");
  std::string rel = r.path == "/" ? "index.html" : r.path.substr(1);
  // Only plain names below the web folder: no "..", no hidden files.
  for (const std::string& part : split(rel)) {
    if (part == ".." || part.front() == '.') return notFound("file " + r.path);
  }
  const fs::path p = fs::path(options.web_dir) / rel;
  static const std::map<std::string, std::string> kTypes = {
      {".html", "text/html; charset=utf-8"}, {".js", "text/javascript"}, {".mjs", "text/javascript"},
      {".css", "text/css"},                  {".json", "application/json"}, {".geojson", "application/geo+json"},
      {".svg", "image/svg+xml"},             {".png", "image/png"},       {".pbf", "application/x-protobuf"}};
  const auto it = kTypes.find(p.extension().string());
  return fileResponse(p, it == kTypes.end() ? "application/octet-stream" : it->second);
}

// --- the public class ------------------------------------------------------------------------

Service::Service(ServeOptions options, Log log) : impl_(std::make_unique<ServiceImpl>(std::move(options), std::move(log))) {}
Service::~Service() = default;
unsigned short Service::port() const { return impl_->server->port(); }
void Service::addInput(std::unique_ptr<planner::FixSource> source, const std::string& flight) {
  if (impl_->nats) {
    throw std::invalid_argument("--input " + source->name() + ": with --nats, fixes go to the workers: publish them to skylane.fix.<operator>.<flight> (skylane nats publish)");
  }
  impl_->inputs.push_back(std::make_unique<ServiceImpl::Input>(ServiceImpl::Input{std::move(source), flight, {}}));
}
void Service::run() {
  for (auto& in : impl_->inputs) {
    if (!in->thread.joinable()) impl_->startInput(*in);
  }
  impl_->server->run();
}
void Service::stop() {
  impl_->stopping = true;
  impl_->server->stop();
}

}  // namespace skylane::service
