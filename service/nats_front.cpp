#include "service/nats_front.hpp"

#include "maps/atomic_file.hpp"
#include "service/approval_bundle.hpp"
#include "service/nats_layout.hpp"

#include <nlohmann/json.hpp>

#include <random>
#include <sstream>

namespace skylane::service {

namespace {

using nlohmann::json;

/// A consumer name no other reader uses.
std::string uniqueName(const char* prefix) {
  static std::random_device rd;
  static std::mt19937_64 gen(rd());
  std::ostringstream s;
  s << prefix << std::hex << gen();
  return s.str();
}

void writeOutput(const std::filesystem::path& p, const std::string& text) {
  maps::AtomicFile f(p.string(), "the service folder");
  f.stream() << text;
  f.commit();
}

/// A reader that stopped fetching (its service died) leaves no consumer behind for long.
constexpr std::chrono::seconds kReaderInactive{60};

}  // namespace

StreamEvent streamEvent(const NatsMessage& m) {
  StreamEvent e;
  const std::vector<std::string> t = nats::subjectTokens(m.subject);
  if (t.size() == 4) {
    e.op = t[2];
    e.event.flight = t[3];
  }
  e.event.seq = static_cast<std::int64_t>(m.stream_seq);
  e.event.line = m.data;
  try {
    const json j = json::parse(m.data);
    e.event.type = j.is_object() && j.contains("event") && j["event"].is_string() ? j["event"].get<std::string>() : "unknown";
  } catch (const json::exception&) {
    e.event.type = "unknown";
  }
  return e;
}

NatsFront::NatsFront(const std::string& url, Log log, OnEvent on_event) : log_(std::move(log)), on_event_(std::move(on_event)) {
  nats_ = std::make_unique<NatsClient>(url, "skylane-serve");
  (void)nats::partitionCount(*nats_);  // set up by `skylane nats setup`
  reader_ = std::make_unique<NatsClient>(url, "skylane-serve-events");
  const std::uint64_t from = nats_->lastSequence(nats::kEventStream) + 1;
  thread_ = std::thread([this, from] { readEvents(from); });
}

NatsFront::~NatsFront() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
}

void NatsFront::readEvents(std::uint64_t from) {
  const std::string durable = uniqueName("serve-");
  std::unique_ptr<NatsPull> pull;
  while (!stopping_) {
    try {
      if (!pull) pull = reader_->pullFrom(nats::kEventStream, durable, "skylane.event.>", from, kReaderInactive);
      for (const NatsMessage& m : pull->fetch(256, std::chrono::milliseconds(250))) {
        from = m.stream_seq + 1;
        on_event_(streamEvent(m));
      }
    } catch (const NatsError& e) {
      if (stopping_) break;
      log_(std::string("NATS event stream: ") + e.what() + "; reading again from " + std::to_string(from));
      pull.reset();
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
  try {
    pull.reset();
    reader_->deleteConsumer(nats::kEventStream, durable);
  } catch (const NatsError&) {
    // the server removes it after kReaderInactive
  }
}

void NatsFront::requestApproval(const std::string& op, const std::string& id, const std::string& mission_path) {
  const ApprovalBundle b = packMission(mission_path);
  (void)nats_->publish(nats::approvalSubject(op, id), bundleText(b), "request." + op + "." + id);
}

std::optional<NatsApprovalOutcome> NatsFront::takeApprovalOutcome(const std::string& op, const std::string& id,
                                                                  const std::filesystem::path& dir) {
  const std::string key = op + "." + id;
  const auto st = nats_->get(nats::kApprovalBucket, key);
  if (!st) return std::nullopt;
  const json j = json::parse(st->value);
  NatsApprovalOutcome out{j.value("status", ""), j.value("message", "")};
  if (out.status == "queued" || out.status == "running" || out.status.empty()) return std::nullopt;
  if (const auto b = nats_->get(nats::kApprovalBucket, key + ".bundle")) {
    writeOutput(dir / "report.json", parseBundle(b->value, "approval bundle " + key).report);
  }
  if (const auto r = nats_->get(nats::kApprovalBucket, key + ".route")) writeOutput(dir / "route.geojson", r->value);
  for (const std::string name : {"operational_intent.json", "mission.plan", "map.svg", "pl.svg"}) {
    if (const auto f = nats_->get(nats::kApprovalBucket, key + ".out." + name)) writeOutput(dir / name, f->value);
  }
  return out;
}

std::uint64_t NatsFront::putZoneSet(const std::string& key, const std::string& text) {
  if (const auto e = nats_->get(nats::kZoneSetBucket, key); e && e->value == text) return e->revision;
  return nats_->put(nats::kZoneSetBucket, key, text);
}

void NatsFront::startFlight(const std::string& op, const std::string& flight, const std::string& approval) {
  (void)nats_->publish(nats::fixSubject(op, flight), json{{"start", {{"approval", approval}}}}.dump(), "start." + op + "." + flight);
}

void NatsFront::publishFixes(const std::string& op, const std::string& flight, const std::vector<std::string>& lines) {
  const std::string subject = nats::fixSubject(op, flight);
  for (const std::string& line : lines) nats_->publishAsync(subject, line);
  nats_->publishesComplete();
}

void NatsFront::publishEvent(const std::string& op, const std::string& flight, const std::string& json_line, const std::string& msg_id) {
  (void)nats_->publish(nats::eventSubject(op, flight), json_line, msg_id);
}

std::optional<json> NatsFront::flightCheckpoint(const std::string& op, const std::string& flight) {
  const auto e = nats_->get(nats::kFlightBucket, op + "." + flight);
  if (!e) return std::nullopt;
  return json::parse(e->value);
}

std::optional<json> NatsFront::flightRouteGeoJson(const std::string& op, const std::string& flight) {
  const auto e = nats_->get(nats::kFlightBucket, op + "." + flight + ".geojson");
  if (!e) return std::nullopt;
  return json::parse(e->value);
}

std::vector<StreamEvent> NatsFront::eventsAfter(const std::string& filter, std::uint64_t after, std::size_t max_bytes) {
  const std::uint64_t last = nats_->lastSequence(nats::kEventStream);
  std::vector<StreamEvent> out;
  if (after >= last) return out;
  const std::string durable = uniqueName("serve-read-");
  auto pull = nats_->pullFrom(nats::kEventStream, durable, filter, after + 1, kReaderInactive);
  std::size_t bytes = 0;
  bool done = false;
  while (!done) {
    const std::vector<NatsMessage> batch = pull->fetch(256, std::chrono::milliseconds(200));
    for (const NatsMessage& m : batch) {
      if (m.stream_seq > last) {
        done = true;
        break;
      }
      bytes += m.data.size();
      out.push_back(streamEvent(m));
    }
    if (bytes > max_bytes) {
      nats_->deleteConsumer(nats::kEventStream, durable);
      throw std::length_error("more than " + std::to_string(max_bytes >> 20) + " MiB of events");
    }
    done = done || batch.empty() || (!out.empty() && out.back().event.seq >= static_cast<std::int64_t>(last)) ||
           nats_->pending(nats::kEventStream, durable) == 0;
  }
  pull.reset();
  nats_->deleteConsumer(nats::kEventStream, durable);
  return out;
}

}  // namespace skylane::service
