/// \file
/// \brief The service with `--nats`: approvals go to the approve workers' work queue, a flight's
/// start and its fixes to its fix subject, and the track workers' events come back from the event
/// stream to the flights' event streams (their Server-Sent Events ids the stream sequence, so a
/// reader resumes with Last-Event-ID from the stream itself). The service's database keeps what
/// is the service's: zone sets, approvals, which operator owns which flight.

#include "planner/tracking/fix_source.hpp"
#include "planner/tracking/flight_state.hpp"
#include "planner/tracking/track_event.hpp"
#include "maps/text_file.hpp"
#include "service/nats_layout.hpp"
#include "service/service_impl.hpp"

namespace skylane::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// How often approvals still out are looked up (an outcome whose event came while the event
/// reader was reconnecting is found this way).
constexpr std::chrono::seconds kApprovalPoll{2};

/// The approve worker's status word as the exit status of `skylane approve` it stands for.
ApprovalOutcome outcomeOf(const NatsApprovalOutcome& o) {
  if (o.status == "approved") return {0, ""};
  if (o.status == "rejected") return {1, ""};
  if (o.status == "invalid") return {2, o.message};
  return {-1, o.message.empty() ? "the approve worker failed" : o.message};
}

}  // namespace

void ServiceImpl::startNats() {
  for (const auto& op : tokens.operators()) {
    if (!nats::validId(op)) {
      throw std::runtime_error("--tokens " + options.tokens + ": operator \"" + op.substr(0, 64) +
                               "\" cannot be a NATS subject token (1–64 of A–Z a–z 0–9 - _, not starting with _)");
    }
  }
  try {
    nats = std::make_unique<NatsFront>(options.nats_url, log, [this](StreamEvent e) {
      server->post([this, e = std::move(e)] { natsEvent(e); });
    });
    // The sets uploaded before (or while NATS was away) are put in, so the workers follow them.
    for (const ZoneSet& z : store->zoneSets()) natsPutZoneSet(z);
  } catch (const std::exception& e) {
    throw std::runtime_error("--nats " + options.nats_url + ": " + e.what());
  }
  server->every(kApprovalPoll, [this] {
    for (auto& [id, a] : approvals) {
      if (a.row.status == "queued" || a.row.status == "running") (void)natsTakeOutcome(a);
    }
  });
}

std::string ServiceImpl::natsZoneSetKey(const ZoneSet& z) { return (z.owner.empty() ? std::string("authority") : z.owner) + "." + z.id; }

void ServiceImpl::natsPutZoneSet(const ZoneSet& z) {
  const std::string text = maps::readTextFile((files / z.latest().file).string());
  const std::uint64_t rev = nats->putZoneSet(natsZoneSetKey(z), text);
  log("zone set " + z.id + " version " + std::to_string(z.latest().version) + " is " + natsZoneSetKey(z) + " revision " + std::to_string(rev) + " in NATS");
}

void ServiceImpl::natsWriteMission(const fs::path& dir, json mission, const std::vector<std::string>& follow) {
  json zones = json::array(), sets = json::array();
  for (std::size_t i = 0; i < mission["zones"].size(); ++i) {
    if (i < follow.size() && !follow[i].empty()) {
      sets.push_back(follow[i]);
    } else {
      zones.push_back(mission["zones"][i]);
    }
  }
  mission["zones"] = zones;
  if (!sets.empty()) mission["zonesets"] = sets;
  writeFileAtomically(dir / "nats_mission.json", mission.dump(1) + "\n");
}

void ServiceImpl::natsEvent(const StreamEvent& e) {
  if (e.event.type == "approval") {
    const auto it = approvals.find(e.event.flight);
    if (it != approvals.end() && it->second.row.owner == e.op) (void)natsTakeOutcome(it->second);
    return;
  }
  const auto it = flights.find(e.event.flight);
  if (it == flights.end() || it->second.owner != e.op) return;  // a flight of another front
  hub->publish(e.event);
}

bool ServiceImpl::natsTakeOutcome(ApprovalState& a) {
  if (a.row.status != "queued" && a.row.status != "running") return true;
  std::optional<NatsApprovalOutcome> out;
  try {
    out = nats->takeApprovalOutcome(a.row.owner, a.row.id, files / a.row.dir);
  } catch (const std::exception& e) {
    log("approval " + a.row.id + ": its outcome cannot be read from NATS yet: " + e.what());
    return false;
  }
  if (!out) return false;
  approvalDone(a.row.id, outcomeOf(*out));
  return true;
}

HttpResponse ServiceImpl::natsPostFixes(const FlightRow& f, std::vector<std::string> lines) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<std::string> text = lines;
  planner::JsonLinesFixSource source(std::make_unique<planner::MemoryLineInput>("request", std::move(lines)));
  std::vector<std::string> good;
  std::string refused;
  const auto refuse = [&](const std::string& where, std::size_t line, const std::string& why) {
    planner::TrackEvent e = planner::rejectedInputEvent(where, line, why);
    e.flight = f.id;
    const std::string j = e.toJson().dump();
    nats->publishEvent(f.owner, f.id, j, "refused." + f.id + "." + std::to_string(t0.time_since_epoch().count()) + "." + std::to_string(line));
    refused += (refused.empty() ? "" : ",") + j;
  };
  std::size_t rejected = 0;
  try {
    for (planner::SourceRecord rec = source.next(0); rec.kind != planner::SourceRecord::Kind::kEnd; rec = source.next(0)) {
      if (rec.kind == planner::SourceRecord::Kind::kBad) {
        refuse(rec.where, rec.line, rec.error);
        ++rejected;
      } else if (rec.kind == planner::SourceRecord::Kind::kFix && !rec.fix.flight.empty() && rec.fix.flight != f.id) {
        refuse(rec.fix.source, rec.fix.line, "the line names flight \"" + rec.fix.flight.substr(0, 64) + "\", not " + f.id);
        ++rejected;
      } else if (rec.kind == planner::SourceRecord::Kind::kFix) {
        good.push_back(text.at(rec.fix.line - 1));
      }
    }
    nats->publishFixes(f.owner, f.id, good);
  } catch (const NatsError& e) {
    return errorResponse(503, std::string("NATS: ") + e.what() + "; the fixes after the first " + std::to_string(good.size()) +
                                  " may not be kept: send them again");
  }
  metrics.fix_request_seconds.observe(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  // The fixes are in the stream (acknowledged by the server); their events come on the event
  // stream from the track worker of the flight's partition.
  return jsonResponse(200, "{\"accepted\":" + std::to_string(good.size()) + ",\"rejected\":" + std::to_string(rejected) +
                               ",\"events\":[" + refused + "]}\n");
}

json ServiceImpl::natsFlightState(const FlightRow& f) const {
  std::optional<json> cp;
  try {
    cp = nats->flightCheckpoint(f.owner, f.id);
  } catch (const NatsError& e) {
    log("flight " + f.id + ": no checkpoint from NATS: " + e.what());
  }
  if (!cp || !cp->contains("state")) return planner::flightStateJson(planner::FlightState{});
  json st = cp->at("state");
  st["checkpoint_fix_seq"] = cp->value("seq", 0);
  return st;
}

HttpResponse ServiceImpl::natsRoute(const FlightRow& f) const {
  std::optional<json> route;
  try {
    route = nats->flightRouteGeoJson(f.owner, f.id);
  } catch (const NatsError& e) {
    return errorResponse(503, std::string("NATS: ") + e.what());
  }
  if (!route) {  // not replanned (as of its checkpoint): the approved route
    const auto a = approvals.find(f.approval);
    if (a == approvals.end()) return notFound("route of flight " + f.id);
    return fileResponse(files / a->second.row.dir / "route.geojson", "application/geo+json");
  }
  HttpResponse res = jsonBody(200, *route);
  res.content_type = "application/geo+json";
  return res;
}

std::optional<HttpResponse> ServiceImpl::natsBacklog(const Principal& who, const std::string& flight, std::int64_t after,
                                                     const std::function<bool(const std::string&)>& wants, std::string& body,
                                                     std::int64_t& sent) const {
  const std::string filter = flight.empty() ? "skylane.event." + who.owner() + ".>" : nats::eventSubject(who.owner(), flight);
  try {
    for (const StreamEvent& e : nats->eventsAfter(filter, static_cast<std::uint64_t>(after), 64u << 20)) {
      sent = std::max(sent, e.event.seq);
      if (e.event.type != "approval" && wants(e.event.flight)) body += sseMessage(e.event);
    }
  } catch (const std::length_error&) {
    return errorResponse(413, "more than 64 MiB of events after " + std::to_string(after) + "; resume from a later id");
  } catch (const NatsError& e) {
    return errorResponse(503, std::string("NATS: ") + e.what());
  }
  return std::nullopt;
}

}  // namespace skylane::service
