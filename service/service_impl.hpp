#pragma once
/// \file
/// \brief The inside of the service (service.hpp): its state and its routes, split over
/// service.cpp (start, restart, dispatch), zone_routes.cpp, approval_routes.cpp and
/// flight_routes.cpp. Everything here runs on the server's one thread, except the approval
/// workers, which hand their results over with HttpServer::post().

#include "airspace/zone.hpp"
#include "planner/tracking/fix_source.hpp"
#include "planner/tracking/tracking_session.hpp"
#include "service/approval_pool.hpp"
#include "service/auth.hpp"
#include "service/event_hub.hpp"
#include "service/metrics.hpp"
#include "service/nats_front.hpp"
#include "service/service.hpp"
#include "service/service_store.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <thread>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::service {

/// \brief The path split at '/', without empty parts ("/v1/flights/x" → v1, flights, x).
using Segments = std::vector<std::string>;

/// \brief An approval as the service holds it.
struct ApprovalState {
  ApprovalRow row;
  std::vector<std::string> progress;
  std::chrono::steady_clock::time_point submitted;
};

/// \brief A zone set with its zones loaded (the latest version; older ones on request).
struct LoadedZoneSet {
  ZoneSet set;
  std::map<int, std::vector<airspace::Zone>> zones;  ///< by version, loaded when first needed
};

class ServiceImpl {
 public:
  ServiceImpl(ServeOptions options, Service::Log log);
  ~ServiceImpl();

  ServeOptions options;
  Service::Log log;
  std::filesystem::path files;  ///< `<db>.files`
  TokenTable tokens;
  RateLimiter limiter;
  Metrics metrics;
  std::unique_ptr<ServiceStore> store;
  std::unique_ptr<planner::TrackingSession> session;
  std::unique_ptr<EventHub> hub;
  std::map<std::string, LoadedZoneSet> zonesets;
  std::map<std::string, ApprovalState> approvals;
  std::map<std::string, FlightRow> flights;
  std::map<std::string, std::string> last_fix;  ///< each flight's last `fix` event (its JSON line)
  std::unique_ptr<ApprovalPool> pool;
  /// Fix inputs besides HTTP, each read on its own thread (Service::addInput).
  struct Input {
    std::unique_ptr<planner::FixSource> source;
    std::string flight;
    std::thread thread;
  };
  std::vector<std::unique_ptr<Input>> inputs;
  std::atomic<bool> stopping{false};
  void startInput(Input& in);
  void takeRecord(const planner::SourceRecord& r, const std::string& input_flight);
  std::unique_ptr<HttpServer> server;
  std::unique_ptr<NatsFront> nats;  ///< with --nats: the workers do the engine's work

  // nats_routes.cpp (with --nats)
  void startNats();
  void natsEvent(const StreamEvent& e);
  /// The zone set's NATS key: `authority.<id>` or `<operator>.<id>`.
  [[nodiscard]] static std::string natsZoneSetKey(const ZoneSet& z);
  /// Puts the set's latest version into the NATS zone set bucket (when it differs from the one there).
  void natsPutZoneSet(const ZoneSet& z);
  /// The mission the approve worker gets: the zone sets named without a version by their NATS keys
  /// (resolved to their current versions by the worker, and followed by the track workers).
  void natsWriteMission(const std::filesystem::path& dir, nlohmann::json mission, const std::vector<std::string>& follow);
  /// The approval's outcome when the workers have it; false while it is still to come.
  bool natsTakeOutcome(ApprovalState& a);
  HttpResponse natsPostFixes(const FlightRow& f, std::vector<std::string> lines);
  [[nodiscard]] nlohmann::json natsFlightState(const FlightRow& f) const;
  HttpResponse natsRoute(const FlightRow& f) const;
  /// The events on NATS after `after` that `wants` accepts, as Server-Sent Events text; `sent`:
  /// the last sequence of the operator's events read (so a live one up to it is not sent again).
  std::optional<HttpResponse> natsBacklog(const Principal& who, const std::string& flight, std::int64_t after,
                                          const std::function<bool(const std::string&)>& wants, std::string& body,
                                          std::int64_t& sent) const;

  // service.cpp
  HttpResponse handle(const HttpRequest& r);
  HttpResponse route(const HttpRequest& r);
  HttpResponse routeV1(const HttpRequest& r, const Principal& who, const Segments& s);
  HttpResponse serveStatic(const HttpRequest& r) const;
  HttpResponse readiness() const;
  void restore();
  void addGauges();

  // zone_routes.cpp
  HttpResponse zoneSets(const HttpRequest& r, const Principal& who, const Segments& s);
  HttpResponse uploadZoneSet(const HttpRequest& r, const Principal& who, const std::string& id);
  HttpResponse zoneSetGeoJson(const HttpRequest& r, const Principal& who, const std::string& id);
  HttpResponse zonesQuery(const HttpRequest& r, const Principal& who);
  /// The set when `who` may read it (public, or its own), else nullptr.
  LoadedZoneSet* visibleZoneSet(const Principal& who, const std::string& id);
  const std::vector<airspace::Zone>& zonesOf(LoadedZoneSet& z, int version);

  // approval_routes.cpp
  HttpResponse approvalsRoute(const HttpRequest& r, const Principal& who, const Segments& s);
  HttpResponse submitApproval(const HttpRequest& r, const Principal& who);
  HttpResponse approvalStatus(const ApprovalState& a) const;
  HttpResponse approvalFile(const ApprovalState& a, const std::string& name) const;
  /// The mission as `skylane approve` reads it: zone set ids → their files; orbits → the orbits folder.
  /// `follow` (when given): for each of the mission's zone files, the NATS zone set key it stands
  /// for when the mission named its set without a version (the set's later versions are followed),
  /// else "".
  nlohmann::json resolveMission(const nlohmann::json& body, const Principal& who, std::vector<std::string>* follow = nullptr);
  void queueApproval(ApprovalState& a);
  void approvalDone(const std::string& id, const ApprovalOutcome& outcome);

  // orbit_routes.cpp
  HttpResponse orbitsRoute(const HttpRequest& r, const Principal& who, const Segments& s);
  /// The file a mission's orbit name means for `who`: its own upload, the authority's, or the
  /// service's orbits folder.
  [[nodiscard]] std::optional<std::filesystem::path> orbitFile(const Principal& who, const std::string& name) const;

  // flight_routes.cpp
  HttpResponse flightsRoute(const HttpRequest& r, const Principal& who, const Segments& s);
  HttpResponse startFlight(const HttpRequest& r, const Principal& who);
  HttpResponse postFixes(const HttpRequest& r, const FlightRow& f);
  HttpResponse flightJson(const FlightRow& f) const;
  [[nodiscard]] nlohmann::json flightObject(const FlightRow& f) const;
  HttpResponse eventStream(const HttpRequest& r, const Principal& who, const std::string& flight);
  [[nodiscard]] bool owns(const Principal& who, const std::string& flight) const;
};

// Helpers shared by the route files (service.cpp).
[[nodiscard]] std::string newId(const char* prefix);
[[nodiscard]] std::string nowUtc();
/// \brief 415 unless the request's body is one of `types` (media type before any parameter).
[[nodiscard]] std::optional<HttpResponse> requireContentType(const HttpRequest& r, std::initializer_list<const char*> types);
/// \brief 405 naming the methods allowed.
[[nodiscard]] HttpResponse methodNotAllowed(const std::string& allow);
/// \brief 404 "no such …".
[[nodiscard]] HttpResponse notFound(const std::string& what);
/// \brief A JSON value as a 200/201 body.
[[nodiscard]] HttpResponse jsonBody(int status, const nlohmann::json& j);
/// \brief Writes a file whole or not at all: a temporary name in the same folder, flushed to
/// disk, then renamed (maps/atomic_file.hpp). \throws maps::OutputError naming the file.
void writeFileAtomically(const std::filesystem::path& p, const std::string& text);
/// \brief The OpenAPI 3 document of the API (service/openapi.json, built in).
[[nodiscard]] const std::string& openApiDocument();
/// \brief A file's contents, or 404.
[[nodiscard]] HttpResponse fileResponse(const std::filesystem::path& p, const std::string& content_type);

}  // namespace skylane::service
