/// \file
/// \brief Flights: tracking an approved flight, its fixes (one or a batch of JSON lines per
/// request, judged and committed before the answer, so an acknowledged fix is never lost), its
/// state and current route, and its events as Server-Sent Events resumable with Last-Event-ID.

#include "planner/tracking/fix_source.hpp"
#include "planner/tracking/flight_state.hpp"
#include "service/service_impl.hpp"

#include <algorithm>

namespace skylane::service {

namespace fs = std::filesystem;
using nlohmann::json;

bool ServiceImpl::owns(const Principal& who, const std::string& flight) const {
  const auto it = flights.find(flight);
  return it != flights.end() && it->second.owner == who.owner();
}

HttpResponse ServiceImpl::flightsRoute(const HttpRequest& r, const Principal& who, const Segments& s) {
  if (s.size() == 2) {
    if (r.method == "POST") return startFlight(r, who);
    if (r.method != "GET") return methodNotAllowed("GET, POST");
    json list = json::array();
    for (const auto& [id, f] : flights) {
      if (f.owner == who.owner()) list.push_back(flightObject(f));
    }
    return jsonBody(200, {{"flights", list}});
  }
  if (!owns(who, s[2])) return notFound("flight " + s[2]);
  const FlightRow& f = flights.at(s[2]);
  const std::string part = s.size() == 4 ? s[3] : std::string();
  if (s.size() > 4) return notFound("route " + r.path);
  if (part == "fixes") return r.method == "POST" ? postFixes(r, f) : methodNotAllowed("POST");
  if (r.method != "GET") return methodNotAllowed("GET");
  if (part.empty()) return flightJson(f);
  if (part == "events") return eventStream(r, who, f.id);
  if (part == "route") {
    if (nats) return natsRoute(f);
    HttpResponse res = jsonBody(200, session->tracker().routeGeoJson(f.id));
    res.content_type = "application/geo+json";
    return res;
  }
  return notFound("route " + r.path);
}

HttpResponse ServiceImpl::startFlight(const HttpRequest& r, const Principal& who) {
  if (who.authority) return errorResponse(403, "flights are an operator's: the authority's token starts none");
  if (auto bad = requireContentType(r, {"application/json"})) return *bad;
  json body;
  try {
    body = maps::parseJsonText(r.body, "the request body");
  } catch (const std::exception& e) {
    return errorResponse(400, e.what());
  }
  if (!body.is_object() || !body.contains("approval") || !body["approval"].is_string()) {
    return errorResponse(400, "$.approval: expected the id of an approved approval (\"ap-…\")");
  }
  const std::string ap = body["approval"].get<std::string>();
  const auto it = approvals.find(ap);
  if (it == approvals.end() || it->second.row.owner != who.owner()) return notFound("approval " + ap.substr(0, 64));
  if (it->second.row.status != "approved") return errorResponse(409, "approval " + ap + " is " + it->second.row.status + ", not approved");
  const std::string id = newId("fl-");
  try {
    if (nats) {
      nats->startFlight(who.owner(), id, ap);
    } else {
      session->addApprovalFile((files / it->second.row.dir / "report.json").string(), id);
    }
  } catch (const NatsError& e) {
    return errorResponse(503, std::string("NATS: ") + e.what());
  } catch (const std::exception& e) {
    return errorResponse(409, std::string("approval ") + ap + " cannot be tracked: " + e.what());
  }
  const FlightRow row{id, who.owner(), ap, nowUtc()};
  store->addFlight(row);
  flights[id] = row;
  log("flight " + id + " of approval " + ap + " tracked for " + who.owner());
  HttpResponse res = flightJson(row);
  res.status = 201;
  res.headers.emplace_back("Location", "/v1/flights/" + id);
  return res;
}

nlohmann::json ServiceImpl::flightObject(const FlightRow& f) const {
  nlohmann::json j = {{"id", f.id}, {"approval", f.approval}, {"created", f.created}};
  j["state"] = nats ? natsFlightState(f) : planner::flightStateJson(session->tracker().state(f.id));
  if (const auto it = last_fix.find(f.id); it != last_fix.end()) j["last_fix"] = nlohmann::json::parse(it->second);
  return j;
}

HttpResponse ServiceImpl::flightJson(const FlightRow& f) const { return jsonBody(200, flightObject(f)); }

HttpResponse ServiceImpl::postFixes(const HttpRequest& r, const FlightRow& f) {
  if (auto bad = requireContentType(r, {"application/x-ndjson", "application/jsonl", "application/json"})) return *bad;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> lines;
  for (std::size_t i = 0; i <= r.body.size();) {
    const std::size_t nl = std::min(r.body.find('\n', i), r.body.size());
    lines.push_back(r.body.substr(i, nl - i));
    i = nl + 1;
  }
  if (lines.size() > options.max_fixes_per_request) {
    return errorResponse(413, "a request of " + std::to_string(lines.size()) + " lines; at most " +
                                  std::to_string(options.max_fixes_per_request) + " fixes per request");
  }
  if (nats) return natsPostFixes(f, std::move(lines));
  std::vector<HubEvent> mine;
  hub->observers.push_back([&mine](const HubEvent& e) { mine.push_back(e); });
  struct Unobserve {
    EventHub& hub;
    ~Unobserve() { hub.observers.pop_back(); }
  } unobserve{*hub};
  planner::JsonLinesFixSource source(std::make_unique<planner::MemoryLineInput>("request", std::move(lines)));
  std::size_t accepted = 0, rejected = 0;
  for (planner::SourceRecord rec = source.next(0); rec.kind != planner::SourceRecord::Kind::kEnd; rec = source.next(0)) {
    if (rec.kind == planner::SourceRecord::Kind::kBad) {
      session->reject(rec.where, rec.line, rec.error, f.id);
      ++rejected;
    } else if (rec.kind == planner::SourceRecord::Kind::kFix) {
      if (!rec.fix.flight.empty() && rec.fix.flight != f.id) {
        session->reject(rec.fix.source, rec.fix.line, "the line names flight \"" + rec.fix.flight.substr(0, 64) + "\", not " + f.id, f.id);
        ++rejected;
        continue;
      }
      rec.fix.flight = f.id;
      session->submit(rec.fix);
      ++accepted;
    }
  }
  session->commit();
  metrics.fix_request_seconds.observe(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  // The events as the engine wrote them (each a JSON object on one line), not parsed again.
  std::string body = "{\"accepted\":" + std::to_string(accepted) + ",\"rejected\":" + std::to_string(rejected) + ",\"events\":[";
  bool first = true;
  for (const HubEvent& e : mine) {
    if (e.flight != f.id) continue;
    body += (first ? "" : ",") + e.line;
    first = false;
  }
  return jsonResponse(200, body + "]}\n");
}

HttpResponse ServiceImpl::eventStream(const HttpRequest& r, const Principal& who, const std::string& flight) {
  std::int64_t after = -1;
  const std::string last = r.header("last-event-id").empty() ? r.param("after") : r.header("last-event-id");
  if (!last.empty()) {
    const bool digits = last.size() < 19 && std::all_of(last.begin(), last.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits) return errorResponse(400, "Last-Event-ID \"" + last.substr(0, 32) + "\": expected the id of an event (a number)");
    after = std::stoll(last);
  }
  auto wants = [this, who, flight](const std::string& f) { return flight.empty() ? owns(who, f) : f == flight; };
  HttpResponse res;
  res.content_type = "text/event-stream";
  res.stream = std::make_shared<EventStream>();
  res.body = "retry: 1000\n\n";
  // What the reader missed comes first, from the database (or the NATS event stream); then the
  // live events, none of them twice.
  std::int64_t sent = std::max<std::int64_t>(after, 0);
  if (after >= 0 && nats) {
    if (auto bad = natsBacklog(who, flight, after, wants, res.body, sent)) return *bad;
  } else if (after >= 0) {
    for (std::int64_t from = after;;) {
      const auto batch = session->store()->eventsAfter(from, 1000);
      for (const auto& e : batch) {
        if (wants(e.flight)) res.body += sseMessage({e.seq, e.flight, e.type, e.line});
      }
      if (batch.size() < 1000) break;
      from = batch.back().seq;
      if (res.body.size() > (64u << 20)) return errorResponse(413, "more than 64 MiB of events after " + last + "; resume from a later id");
    }
  }
  hub->subscribe(res.stream, flight, wants, sent);
  return res;
}

}  // namespace skylane::service
