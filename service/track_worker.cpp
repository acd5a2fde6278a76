#include "service/track_worker.hpp"

#include "maps/atomic_file.hpp"
#include "maps/file_digest.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "planner/mission.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/flight_state.hpp"
#include "planner/tracking/track_event.hpp"
#include "service/approval_bundle.hpp"
#include "service/nats_layout.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

namespace skylane::service {

namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

/// A flight of a held partition: who it belongs to and how far its checkpoint goes.
struct FlightSlot {
  std::string op, flight, approval;  ///< approval empty: not started
  std::string approval_dir;          ///< where its approval is unpacked
  std::uint64_t covered_seq = 0;     ///< the last fix sequence its checkpoint covers
  int checkpointed_route = 0;        ///< the route version last put with it
  bool dirty = false;
};

/// The zone sets an approval's zones come from, and one of its flights (the approver is shared).
struct ApprovalZones {
  std::string flight;
  std::map<std::string, ApprovalBundle::ZoneSetFile> zonesets;
};

/// A partition the worker may hold.
struct Partition {
  int index = 0;
  bool held = false;
  std::uint64_t lease_rev = 0, checkpoint_rev = 0, covered_seq = 0;
  std::uint64_t deliveries = 0;  ///< messages taken from the consumer since it was made
  std::uint64_t judged_seq = 0;  ///< the last fix sequence judged (its events kept)
  std::unique_ptr<NatsPull> pull;
  std::unique_ptr<planner::Tracker> tracker;
  std::map<std::string, FlightSlot> flights;  ///< by tracker id "<operator>.<flight>"
  std::map<std::string, ApprovalZones> approvals;  ///< by unpacked folder, those with zone sets
  /// The flights with a checkpoint when the partition was taken: any other is new (no lookup).
  std::set<std::string> known;
  /// Each approval's report and approver, read once for all its flights (by unpacked folder).
  std::map<std::string, std::pair<planner::ApprovedFlight, std::shared_ptr<planner::Approver>>> loaded;
};

/// An event to publish.
struct Outgoing {
  std::string subject, data, msg_id;
};

/// A message that cannot be judged: why, for its rejected_input event.
struct Rejected {
  std::string why;
};

class Worker {
 public:
  Worker(const TrackWorkerOptions& o, TrackWorkerCounters& c) : o_(o), c_(c), nats_(o.url, o.name) {}
  void run(const std::atomic<bool>& stop);

 private:
  void log(const std::string& s) const {
    if (o_.log) o_.log(s);
  }
  void choosePartitions();
  std::size_t fairShare();
  void refreshLeases();
  bool acquire(Partition& p);
  void drop(Partition& p, const std::string& why);
  /// A partition's batch taken in a round.
  struct Taken {
    Partition* p;
    std::vector<NatsMessage> msgs;
  };
  std::vector<Taken> fetchRound(std::chrono::milliseconds wait);
  bool runRound(std::chrono::milliseconds wait);
  void putFlightCheckpoints(Partition& p);
  bool putPartitionCheckpoint(Partition& p, std::uint64_t last_seq);
  void judge(Partition& p, const NatsMessage& m, std::vector<Outgoing>& out);
  void judgeFix(Partition& p, FlightSlot& slot, const NatsMessage& m, planner::TrackFix fix, std::vector<Outgoing>& out);
  void startFlight(Partition& p, FlightSlot& slot, const json& body);
  FlightSlot& slotOf(Partition& p, const std::string& op, const std::string& flight);
  FlightSlot& restoreFlight(Partition& p, const std::string& op, const std::string& flight, const json& cp);
  void loadFlightsOf(Partition& p);
  void tellZoneSetsSinceCheckpoint(Partition& p, FlightSlot& slot, const json& cp);
  void tellZoneSet(const std::string& id, FlightSlot& slot, const std::string& name, std::uint64_t version);
  void handOver(Partition& p);
  void loadApproval(Partition& p, FlightSlot& slot, const std::string& id);
  void checkZoneSets();
  void followZoneSets(Partition& p, const std::string& dir, ApprovalZones& a);
  bool tryZoneSetVersion(Partition& p, const std::string& dir, ApprovalZones& a, const std::string& name, const NatsEntry& e,
                         std::string& why);
  void announceZoneSet(Partition& p, const std::string& dir, const std::string& name, std::uint64_t version);
  void checkZoneSetsWhileIdle();
  void sweepStale(Partition& p, std::uint64_t last_seq, std::vector<Outgoing>& out);
  void commit(std::vector<Taken>& taken, const std::vector<Outgoing>& out);
  void checkpointAll();
  void reject(const NatsMessage& m, const std::string& subject, const std::string& why, std::vector<Outgoing>& out);
  void report(Clock::time_point& last) const;

  const TrackWorkerOptions& o_;
  TrackWorkerCounters& c_;
  NatsClient nats_;
  std::vector<Partition> parts_;
  int partition_count_ = 0;
  std::uint64_t zone_seq_ = 0;  ///< the zone set bucket's last sequence when last looked at
  Clock::time_point last_zone_check_{};
  Clock::time_point last_checkpoint_{};
};

std::string leaseKey(int k) { return "p" + std::to_string(k); }

/// How often the flights' and partitions' checkpoints are written (one key-value put per flight
/// judged since: at 1 Hz fixes, a put per flight every period instead of per fix).
constexpr std::chrono::seconds kCheckpointPeriod{2};
/// How often a worker with no fixes coming looks for new zone set versions (one request).
constexpr std::chrono::milliseconds kIdleZoneCheck{250};

void Worker::choosePartitions() {
  const int count = nats::partitionCount(nats_);
  partition_count_ = count;
  std::vector<int> want = o_.partitions;
  if (want.empty()) {
    for (int k = 0; k < count; ++k) want.push_back(k);
  }
  for (int k : want) {
    if (k < 0 || k >= count) {
      throw std::invalid_argument("--partitions: partition " + std::to_string(k) + " is outside 0.." + std::to_string(count - 1) +
                                  " (the count recorded in NATS)");
    }
    Partition p;
    p.index = k;
    parts_.push_back(std::move(p));
  }
}

bool Worker::acquire(Partition& p) {
  std::optional<std::uint64_t> rev;
  if (p.lease_rev != 0) rev = nats_.update(nats::kLeaseBucket, leaseKey(p.index), o_.name, p.lease_rev);
  if (!rev) rev = nats_.create(nats::kLeaseBucket, leaseKey(p.index), o_.name);
  if (!rev) return false;
  p.lease_rev = *rev;
  const auto cp = nats_.get(nats::kPartitionBucket, leaseKey(p.index));
  p.checkpoint_rev = cp ? cp->revision : 0;
  p.covered_seq = cp ? json::parse(cp->value).at("seq").get<std::uint64_t>() : 0;
  p.tracker = std::make_unique<planner::Tracker>(o_.tracker);
  p.flights.clear();
  // Only this partition's holder writes its flights' checkpoints, so a flight without one now is
  // new until this worker writes it: its first message needs no lookup.
  const std::vector<std::string> keys = nats_.keys(nats::kFlightBucket);
  p.known = std::set<std::string>(keys.begin(), keys.end());
  p.deliveries = 0;
  p.judged_seq = p.covered_seq;
  loadFlightsOf(p);
  p.pull = nats_.pullFrom(nats::kFixStream, "track-" + leaseKey(p.index), nats::partitionFilter(p.index), p.covered_seq + 1);
  p.held = true;
  ++c_.partitions_held;
  log("holds partition " + std::to_string(p.index) + " from fix sequence " + std::to_string(p.covered_seq + 1));
  return true;
}

void Worker::drop(Partition& p, const std::string& why) {
  if (!p.held) return;
  log("lets go of partition " + std::to_string(p.index) + ": " + why);
  p.pull.reset();
  p.tracker.reset();
  p.flights.clear();
  p.approvals.clear();
  p.loaded.clear();
  p.known.clear();
  p.held = false;
  --c_.partitions_held;
}

/// The partitions this worker should hold: an even share among the live workers (each keeps a
/// presence key in the lease bucket), so that a second worker gets half and a stopped one's go
/// to the others.
std::size_t Worker::fairShare() {
  nats_.put(nats::kLeaseBucket, "w." + o_.name, "alive");
  std::size_t live = 0;
  for (const std::string& k : nats_.keys(nats::kLeaseBucket)) live += k.rfind("w.", 0) == 0 ? 1 : 0;
  const std::size_t n = std::max<std::size_t>(live, 1);
  return (static_cast<std::size_t>(partition_count_) + n - 1) / n;
}

void Worker::refreshLeases() {
  std::size_t share = parts_.size();
  try {
    share = fairShare();
  } catch (const NatsError& e) {
    log(std::string("NATS: ") + e.what());
  }
  std::size_t held = 0;
  bool released = false;
  for (Partition& p : parts_) {
    try {
      if (!p.held) {
        if (held < share && acquire(p)) ++held;
      } else if (held >= share && !released) {  // more than its share: one goes back each second
        handOver(p);
        drop(p, "another worker takes its share");
        nats_.erase(nats::kLeaseBucket, leaseKey(p.index));
        p.lease_rev = 0;
        released = true;
      } else if (const auto rev = nats_.update(nats::kLeaseBucket, leaseKey(p.index), o_.name, p.lease_rev)) {
        p.lease_rev = *rev;
        ++held;
      } else {
        p.lease_rev = 0;
        drop(p, "its lease was taken");
      }
    } catch (const NatsError& e) {
      drop(p, e.what());
    }
  }
}

FlightSlot& Worker::slotOf(Partition& p, const std::string& op, const std::string& flight) {
  const std::string id = op + "." + flight;
  if (const auto it = p.flights.find(id); it != p.flights.end()) return it->second;
  const auto cp = p.known.count(id) > 0 ? nats_.get(nats::kFlightBucket, id) : std::nullopt;
  if (cp) return restoreFlight(p, op, flight, json::parse(cp->value));
  FlightSlot slot;
  slot.op = op;
  slot.flight = flight;
  return p.flights.emplace(id, std::move(slot)).first->second;
}

/// A flight as its checkpoint `cp` left it: its approval loaded (when it was started), the
/// tracker's state and route restored, and told of zone set versions put in force since.
FlightSlot& Worker::restoreFlight(Partition& p, const std::string& op, const std::string& flight, const json& cp) {
  const std::string id = op + "." + flight;
  FlightSlot slot;
  slot.op = op;
  slot.flight = flight;
  slot.approval = cp.at("approval").get<std::string>();
  slot.covered_seq = cp.at("seq").get<std::uint64_t>();
  if (!slot.approval.empty()) {  // a flight whose messages were all refused has no approval yet
    loadApproval(p, slot, id);
    const planner::FlightState st = planner::parseFlightState(cp.at("state"), "NATS checkpoint of flight " + id);
    json route;
    if (st.route_version > 0) {
      const auto r = nats_.get(nats::kFlightBucket, id + ".route");
      if (r) route = json::parse(r->value);
    }
    p.tracker->restore(id, st, route);
    slot.checkpointed_route = st.route_version;
  }
  FlightSlot& s = p.flights.emplace(id, std::move(slot)).first->second;
  tellZoneSetsSinceCheckpoint(p, s, cp);
  return s;
}

/// The flights of a partition just taken that have a checkpoint, were started and are not at
/// their goal, loaded at once (not at their next fix): a zone set's new version reaches them
/// while they are quiet.
void Worker::loadFlightsOf(Partition& p) {
  for (const std::string& id : p.known) {
    const std::vector<std::string> t = nats::subjectTokens(id);
    if (t.size() != 2 || !nats::validId(t[0]) || !nats::validId(t[1])) continue;  // a route or GeoJSON key
    if (nats::partitionOf(t[0], t[1], partition_count_) != p.index || p.flights.count(id) > 0) continue;
    const auto cp = nats_.get(nats::kFlightBucket, id);
    if (!cp) continue;
    try {
      const json j = json::parse(cp->value);
      if (j.at("approval").get<std::string>().empty() || j.at("state").value("arrived", false)) continue;
      (void)restoreFlight(p, t[0], t[1], j);
    } catch (const Rejected& r) {
      log("partition " + std::to_string(p.index) + ": flight " + id + " not loaded: " + r.why);
    } catch (const NatsError&) {
      throw;
    } catch (const std::exception& e) {
      log("partition " + std::to_string(p.index) + ": flight " + id + " not loaded: " + e.what());
    }
  }
}

/// Before a partition goes to another worker: its flights' and its own checkpoints, so that the
/// next holder starts where this one stopped (and knows every flight at once).
void Worker::handOver(Partition& p) {
  putFlightCheckpoints(p);
  nats_.publishesComplete();
  if (p.judged_seq > p.covered_seq) (void)putPartitionCheckpoint(p, p.judged_seq);
}

/// The approval's bundle, unpacked once per worker into the cache, registered under `id`.
void Worker::loadApproval(Partition& p, FlightSlot& slot, const std::string& id) {
  const fs::path dir = fs::path(o_.cache_dir) / slot.op / slot.approval;
  if (!fs::exists(dir / "report.json")) {
    const std::string key = slot.op + "." + slot.approval + ".bundle";
    const auto b = nats_.get(nats::kApprovalBucket, key);
    if (!b) throw Rejected{"operator " + slot.op + " has no approval \"" + slot.approval + "\" with a report"};
    unpackBundle(parseBundle(b->value, "approval bundle " + key), dir);
  }
  try {
    auto it = p.loaded.find(dir.string());
    if (it == p.loaded.end()) {
      const std::string report = (dir / "report.json").string();
      planner::ApprovedFlight plan = planner::parseApprovalReport(maps::readJsonFile(report), report);
      if (!plan.approved) throw Rejected{"approval \"" + slot.approval + "\" was rejected, not approved"};
      // The mission of the bundle, beside the report (not where the approve worker had it): its
      // zone files are the ones a zone set's new version is written over.
      const std::string mission = (dir / "mission.json").string();
      if (!plan.mission_sha256.empty() && maps::fileSha256Hex(mission) != plan.mission_sha256) {
        throw Rejected{"approval \"" + slot.approval + "\": its bundle's mission is not the one approved (SHA-256 differs)"};
      }
      auto approver = std::make_shared<planner::Approver>(planner::loadMission(mission));
      it = p.loaded.emplace(dir.string(), std::make_pair(std::move(plan), std::move(approver))).first;
    }
    p.tracker->addFlight(id, it->second.first, it->second.second);
  } catch (const Rejected&) {
    throw;
  } catch (const std::exception& e) {
    throw Rejected{std::string("approval \"") + slot.approval + "\": " + e.what()};
  }
  slot.approval_dir = dir.string();
  if (p.approvals.count(slot.approval_dir) == 0) {
    auto sets = readZoneSets(dir);
    if (sets.empty()) return;
    // Brought up to the zone sets' current versions at once: the bundle (or this worker's copy
    // of it) may be older than a version put before this partition came here.
    followZoneSets(p, slot.approval_dir, p.approvals[slot.approval_dir] = {id, std::move(sets)});
  }
}

/// A zone set put since the last look: its new version replaces the file of every approval of a
/// held partition made from it, and their flights' next fixes are judged against it.
void Worker::checkZoneSets() {
  const std::uint64_t last = nats_.lastSequence("KV_" + nats::kZoneSetBucket);
  if (last == zone_seq_) return;
  zone_seq_ = last;
  for (Partition& p : parts_) {
    if (!p.held) continue;
    for (auto& [dir, a] : p.approvals) followZoneSets(p, dir, a);
  }
}

/// Puts the zone set's version `e` in force for the approval unpacked in `dir`; false (the file
/// as it was, `why` said) when the fence cannot use it.
bool Worker::tryZoneSetVersion(Partition& p, const std::string& dir, ApprovalZones& a, const std::string& name, const NatsEntry& e,
                               std::string& why) {
  ApprovalBundle::ZoneSetFile& f = a.zonesets.at(name);
  const std::string path = (fs::path(dir) / f.file).string();
  const std::string before = maps::readTextFile(path);
  maps::writeFileAtomically(path, e.value, "zone set file");
  try {
    p.tracker->reloadZones(a.flight);
  } catch (const std::exception& ex) {
    maps::writeFileAtomically(path, before, "zone set file");
    why = ex.what();
    return false;
  }
  log("partition " + std::to_string(p.index) + ": zone set " + name + " version " + std::to_string(e.revision) + " in force");
  f.version = e.revision;
  announceZoneSet(p, dir, name, f.version);
  return true;
}

void Worker::followZoneSets(Partition& p, const std::string& dir, ApprovalZones& a) {
  for (auto& [name, f] : a.zonesets) {
    const auto e = nats_.get(nats::kZoneSetBucket, name);
    if (!e || e->revision == f.version) continue;
    std::string why;
    if (tryZoneSetVersion(p, dir, a, name, *e, why)) continue;
    // A version the fence cannot use: the newest usable one before it (newer than the one in force
    // here) is what every worker that followed the set has in force, so one that loads the
    // approval only now goes there too.
    const std::vector<NatsEntry> history = nats_.history(nats::kZoneSetBucket, name);
    std::string ignored;
    for (auto it = history.rbegin(); it != history.rend(); ++it) {
      if (it->revision < e->revision && it->revision > f.version && tryZoneSetVersion(p, dir, a, name, *it, ignored)) break;
    }
    log("zone set " + name + " version " + std::to_string(e->revision) + " not taken: " + why);
    const std::string subject = "$KV." + nats::kZoneSetBucket + "." + name;
    json r = planner::rejectedInputEvent(subject, 0, std::string("version ") + std::to_string(e->revision) + " not taken, version " +
                                                         std::to_string(f.version) + " stays in force: " + why).toJson();
    r["subject"] = subject;
    nats_.publishAsync(nats::kRejectedSubject, r.dump(), "zoneset." + name + "." + std::to_string(e->revision));
  }
  maps::writeFileAtomically((fs::path(dir) / "zonesets.json").string(), zoneSetsText(a.zonesets) + "\n", "zone sets");
}

/// Each flight of the approval unpacked in `dir` is told by an event that a zone set's version
/// is in force for it (its next fixes are judged against it).
void Worker::announceZoneSet(Partition& p, const std::string& dir, const std::string& name, std::uint64_t version) {
  for (auto& [id, slot] : p.flights) {
    if (slot.approval_dir == dir) tellZoneSet(id, slot, name, version);
  }
}

/// The zoneset_in_force event of one flight; its checkpoint records the version told.
void Worker::tellZoneSet(const std::string& id, FlightSlot& slot, const std::string& name, std::uint64_t version) {
  const json e = {{"event", "zoneset_in_force"}, {"flight", slot.flight}, {"zoneset", name}, {"version", version}};
  nats_.publishAsync(nats::eventSubject(slot.op, slot.flight), e.dump(), "zoneset." + id + "." + name + "." + std::to_string(version));
  slot.dirty = true;
}

/// A flight loaded from its checkpoint is told of each zone set whose version in force here is
/// not the one its checkpoint records (put while no worker had the flight loaded, or told by a
/// worker that stopped before its next checkpoint: a repeat within the event stream's duplicate
/// window is dropped by its message id).
void Worker::tellZoneSetsSinceCheckpoint(Partition& p, FlightSlot& slot, const json& cp) {
  const auto z = p.approvals.find(slot.approval_dir);
  const auto told = cp.find("zonesets");
  if (z == p.approvals.end() || told == cp.end() || !told->is_object()) return;
  for (const auto& [name, f] : z->second.zonesets) {
    const auto t = told->find(name);
    if (t != told->end() && *t != f.version) tellZoneSet(slot.op + "." + slot.flight, slot, name, f.version);
  }
}

/// A quiet worker looks at the zone sets too (every kIdleZoneCheck), so a new version is in
/// force, and said, before the next fix comes.
void Worker::checkZoneSetsWhileIdle() {
  if (Clock::now() - last_zone_check_ < kIdleZoneCheck) return;
  last_zone_check_ = Clock::now();
  try {
    checkZoneSets();
    nats_.publishesComplete();
  } catch (const std::exception& e) {
    log(std::string("zone sets not looked at: ") + e.what());
  }
}

void Worker::startFlight(Partition& p, FlightSlot& slot, const json& body) {
  if (!slot.approval.empty()) throw Rejected{"flight " + slot.flight + " was started already (approval " + slot.approval + ")"};
  const json& s = body.at("start");
  if (!s.is_object() || !s.contains("approval") || !s["approval"].is_string() || !nats::validId(s["approval"].get<std::string>())) {
    throw Rejected{"$.start: expected {\"approval\": ID} with the id of an approval of this operator"};
  }
  slot.approval = s["approval"].get<std::string>();
  try {
    loadApproval(p, slot, slot.op + "." + slot.flight);
  } catch (...) {
    slot.approval.clear();
    throw;
  }
}

void Worker::reject(const NatsMessage& m, const std::string& subject, const std::string& why, std::vector<Outgoing>& out) {
  json e = planner::rejectedInputEvent(m.subject, 0, why).toJson();
  // The subject it was published to (skylane.fix.<operator>.<flight>), `source` the partition's.
  const std::vector<std::string> t = nats::subjectTokens(m.subject);
  e["subject"] = t.size() == 5 ? nats::fixSubject(t[3], t[4]) : m.subject;
  e["input_seq"] = m.stream_seq;
  out.push_back({subject, e.dump(), "fix." + std::to_string(m.stream_seq) + ".r"});
  ++c_.rejected;
}

void Worker::judgeFix(Partition& p, FlightSlot& slot, const NatsMessage& m, planner::TrackFix fix, std::vector<Outgoing>& out) {
  if (slot.approval.empty()) {
    throw Rejected{"flight " + slot.flight + " of operator " + slot.op + " is not started: its first message is {\"start\": {\"approval\": ID}}"};
  }
  if (!fix.flight.empty() && fix.flight != slot.flight) throw Rejected{"the fix names flight \"" + fix.flight.substr(0, 64) + "\", not " + slot.flight};
  fix.flight = slot.op + "." + slot.flight;
  fix.line = 0;
  const std::vector<json> events = p.tracker->processJson(fix);
  for (std::size_t i = 0; i < events.size(); ++i) {
    json e = events[i];
    e["flight"] = slot.flight;
    e["operator"] = slot.op;
    e["input_seq"] = m.stream_seq;
    if (const auto z = p.approvals.find(slot.approval_dir); z != p.approvals.end()) {
      for (const auto& [name, f] : z->second.zonesets) e["zonesets"][name] = f.version;
    }
    if (e.value("event", "") == "rejected_input") e["subject"] = nats::fixSubject(slot.op, slot.flight);
    out.push_back({nats::eventSubject(slot.op, slot.flight), e.dump(), "fix." + std::to_string(m.stream_seq) + "." + std::to_string(i)});
  }
  ++c_.fixes;
}

void Worker::judge(Partition& p, const NatsMessage& m, std::vector<Outgoing>& out) {
  const std::vector<std::string> t = nats::subjectTokens(m.subject);
  if (t.size() != 5 || !nats::validId(t[3]) || !nats::validId(t[4])) {
    reject(m, nats::kRejectedSubject, "the subject names no operator and flight (skylane.fix.<operator>.<flight>, ids of A-Z a-z 0-9 - _)", out);
    return;
  }
  const std::string subject = nats::eventSubject(t[3], t[4]);
  try {
    FlightSlot& slot = slotOf(p, t[3], t[4]);
    if (m.stream_seq <= slot.covered_seq) {
      ++c_.skipped;
      return;
    }
    slot.covered_seq = m.stream_seq;
    slot.dirty = true;
    // A plain fix line is read directly (planner/tracking/fix_line.cpp); anything else as a document.
    if (std::optional<planner::TrackFix> plain = planner::parsePlainFixLine(m.data, m.subject)) {
      judgeFix(p, slot, m, std::move(*plain), out);
      return;
    }
    const json body = maps::parseJsonLine(m.data, m.subject);
    if (body.is_object() && body.contains("start")) {
      startFlight(p, slot, body);
      out.push_back({subject, json{{"event", "flight_started"}, {"flight", slot.flight}, {"operator", slot.op}, {"approval", slot.approval},
                                   {"input_seq", m.stream_seq}}.dump(), "fix." + std::to_string(m.stream_seq) + ".0"});
    } else {
      judgeFix(p, slot, m, planner::parseTrackFixJson(body, m.subject), out);
    }
  } catch (const Rejected& r) {
    reject(m, subject, r.why, out);
  } catch (const maps::ParseError& e) {
    reject(m, subject, e.what(), out);
  }
}

void Worker::sweepStale(Partition& p, std::uint64_t last_seq, std::vector<Outgoing>& out) {
  const auto now = p.tracker->streamTime();
  if (!now) return;
  for (const planner::TrackEvent& e : p.tracker->sweepStale(*now)) {
    const auto it = p.flights.find(e.flight);
    if (it == p.flights.end()) continue;
    json j = e.toJson();
    j["flight"] = it->second.flight;
    j["operator"] = it->second.op;
    out.push_back({nats::eventSubject(it->second.op, it->second.flight), j.dump(), "stale." + e.flight + "." + std::to_string(last_seq)});
    it->second.dirty = true;
  }
}

/// The flights' checkpoints of a partition judged in this round (put without waiting).
void Worker::putFlightCheckpoints(Partition& p) {
  for (auto& [id, slot] : p.flights) {
    if (!slot.dirty) continue;
    json cp = {{"approval", slot.approval}, {"seq", slot.covered_seq}};
    if (!slot.approval.empty()) {
      const planner::FlightState& st = p.tracker->state(id);
      cp["state"] = planner::flightStateJson(st);
      if (st.route_version != slot.checkpointed_route) {
        nats_.putAsync(nats::kFlightBucket, id + ".route", p.tracker->routeJson(id).dump());
        nats_.putAsync(nats::kFlightBucket, id + ".geojson", p.tracker->routeGeoJson(id).dump());
        slot.checkpointed_route = st.route_version;
      }
    } else {
      cp["state"] = planner::flightStateJson(planner::FlightState{});
    }
    if (const auto z = p.approvals.find(slot.approval_dir); z != p.approvals.end()) {
      for (const auto& [name, f] : z->second.zonesets) cp["zonesets"][name] = f.version;  // the versions it was told
    }
    nats_.putAsync(nats::kFlightBucket, id, cp.dump());
    slot.dirty = false;
  }
}

/// The partition's checkpoint (compare-and-set on its revision): false when another worker has
/// written it since — this one has lost the partition.
bool Worker::putPartitionCheckpoint(Partition& p, std::uint64_t last_seq) {
  const std::string value = json{{"seq", last_seq}, {"worker", o_.name}}.dump();
  const auto rev = p.checkpoint_rev == 0 ? nats_.create(nats::kPartitionBucket, leaseKey(p.index), value)
                                         : nats_.update(nats::kPartitionBucket, leaseKey(p.index), value, p.checkpoint_rev);
  if (!rev) return false;
  p.checkpoint_rev = *rev;
  p.covered_seq = last_seq;
  return true;
}

/// The events of a round, acknowledged (a checkpoint never covers a fix whose events are not
/// kept); every checkpoint_period, the flights' checkpoints and then each partition's. Between
/// checkpoints a crash costs a replay of at most that long (the same events: repeats, dropped).
void Worker::commit(std::vector<Taken>& taken, const std::vector<Outgoing>& out) {
  for (const Outgoing& o : out) nats_.publishAsync(o.subject, o.data, o.msg_id);
  nats_.publishesComplete();
  c_.events += out.size();
  for (Taken& t : taken) t.p->judged_seq = t.msgs.back().stream_seq;
  if (Clock::now() - last_checkpoint_ < kCheckpointPeriod) return;
  checkpointAll();
}

void Worker::checkpointAll() {
  last_checkpoint_ = Clock::now();
  for (Partition& p : parts_) {
    if (p.held) putFlightCheckpoints(p);  // those judged or told of a zone set since the last
  }
  nats_.publishesComplete();
  for (Partition& p : parts_) {
    if (!p.held || p.judged_seq <= p.covered_seq) continue;
    if (!putPartitionCheckpoint(p, p.judged_seq)) drop(p, "another worker checkpointed it");
  }
}

/// Each held partition's next batch. Without acknowledgements a delivery lost with a connection
/// is not sent again: a gap in a consumer's count starts its partition again from its checkpoint.
std::vector<Worker::Taken> Worker::fetchRound(std::chrono::milliseconds wait) {
  std::vector<Taken> taken;
  for (Partition& p : parts_) {
    if (!p.held) continue;
    try {
      std::vector<NatsMessage> msgs = p.pull->fetch(o_.batch, wait);
      for (const NatsMessage& m : msgs) {
        if (m.consumer_seq != ++p.deliveries) {
          throw NatsError("delivery " + std::to_string(m.consumer_seq) + " came where " + std::to_string(p.deliveries) + " was due");
        }
      }
      if (!msgs.empty()) taken.push_back({&p, std::move(msgs)});
    } catch (const std::exception& e) {
      drop(p, e.what());
      ++c_.restarts;
    }
  }
  return taken;
}

/// One round: every held partition's batch judged, then committed together (the round trips to
/// the server are per round, not per partition).
bool Worker::runRound(std::chrono::milliseconds wait) {
  std::vector<Taken> taken = fetchRound(wait);
  if (taken.empty()) return false;
  try {
    checkZoneSets();  // a zone set put before these fixes were fetched is in force for them
    std::vector<Outgoing> out;
    for (Taken& t : taken) {
      for (const NatsMessage& m : t.msgs) judge(*t.p, m, out);
      sweepStale(*t.p, t.msgs.back().stream_seq, out);
    }
    commit(taken, out);
  } catch (const std::exception& e) {  // NATS gone or refused: the partitions start again from their checkpoints
    for (Taken& t : taken) drop(*t.p, e.what());
    ++c_.restarts;
  }
  return true;
}

void Worker::report(Clock::time_point& last) const {
  if (Clock::now() - last < std::chrono::seconds(10)) return;
  last = Clock::now();
  log(std::to_string(c_.partitions_held.load()) + " partitions held, " + std::to_string(c_.fixes.load()) + " fixes judged, " +
      std::to_string(c_.events.load()) + " events, " + std::to_string(c_.rejected.load()) + " rejected, " +
      std::to_string(c_.skipped.load()) + " skipped as judged before");
}

void Worker::run(const std::atomic<bool>& stop) {
  choosePartitions();
  Clock::time_point last_refresh{}, last_report = Clock::now();
  while (!stop.load()) {
    if (Clock::now() - last_refresh >= std::chrono::seconds(1)) {
      refreshLeases();
      last_refresh = Clock::now();
    }
    const int held = c_.partitions_held.load();
    // A fetch waits for a full batch or this long: short, so that a quiet partition does not
    // hold up the others, long enough that a batch gathers the fixes of several milliseconds.
    const auto wait = std::chrono::milliseconds(held > 0 ? std::max(5, 40 / held) : 0);
    if (held > 0 && !runRound(wait)) checkZoneSetsWhileIdle();
    if (held > 0 && Clock::now() - last_checkpoint_ >= kCheckpointPeriod) {
      try {
        checkpointAll();  // a quiet worker's last fixes get their checkpoints too
      } catch (const std::exception& e) {
        for (Partition& p : parts_) drop(p, e.what());
      }
    }
    if (held == 0) std::this_thread::sleep_for(std::chrono::milliseconds(200));
    report(last_report);
  }
  try {
    checkpointAll();  // a clean stop leaves nothing to judge again
  } catch (const std::exception&) {
  }
  for (Partition& p : parts_) {
    if (!p.held) continue;
    drop(p, "stopping");
    try {
      nats_.erase(nats::kLeaseBucket, leaseKey(p.index));
    } catch (const NatsError&) {
    }
  }
  try {
    nats_.erase(nats::kLeaseBucket, "w." + o_.name);
  } catch (const NatsError&) {
  }
}

}  // namespace

void runTrackWorker(const TrackWorkerOptions& options, const std::atomic<bool>& stop, TrackWorkerCounters& counters) {
  // A worker started before its server (or during a restart) waits for it.
  for (int attempt = 0; !stop.load(); ++attempt) {
    try {
      Worker w(options, counters);
      w.run(stop);
      return;
    } catch (const NatsError& e) {
      if (options.log && attempt % 10 == 0) options.log(std::string("waiting for NATS: ") + e.what());
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
}

}  // namespace skylane::service
