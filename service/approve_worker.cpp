#include "service/approve_worker.hpp"

#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "service/approval_bundle.hpp"
#include "service/approval_pool.hpp"
#include "service/nats_layout.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <future>
#include <thread>

namespace skylane::service {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

/// The approval's child process, with the server told every 5 s that the request is in hand.
ApprovalOutcome runApproval(const ApproveWorkerOptions& o, const NatsMessage& m, const fs::path& dir) {
  std::promise<ApprovalOutcome> done;
  ApprovalPool pool(o.program, 1, 1, [](const std::string&, const std::string&) {},
                    [&done](const std::string&, const ApprovalOutcome& out) { done.set_value(out); });
  std::future<ApprovalOutcome> outcome = done.get_future();
  (void)pool.submit({"nats", (dir / "mission.json").string(), (dir / "out").string()});
  while (outcome.wait_for(std::chrono::seconds(5)) != std::future_status::ready) NatsPull::inProgress(m);
  return outcome.get();
}

std::string statusWord(int exit_code, bool has_report) {
  if (exit_code == 0) return "approved";
  if (exit_code == 1 && has_report) return "rejected";
  if (exit_code == 2) return "invalid";
  return "failed";
}

/// The approval's other outputs (what `skylane serve --nats` serves), each as `<key>.out.<name>`;
/// one larger than a message may be is left out and said.
void keepOutputs(const ApproveWorkerOptions& o, NatsClient& nats, const std::string& key, const fs::path& out) {
  for (const std::string name : {"operational_intent.json", "mission.plan", "map.svg", "pl.svg"}) {
    if (!fs::exists(out / name)) continue;
    try {
      nats.put(nats::kApprovalBucket, key + ".out." + name, maps::readTextFile((out / name).string()));
    } catch (const NatsError& e) {
      if (o.log) o.log(key + ": " + name + " not kept: " + e.what());
    }
  }
}

/// Puts the outcome (bundle and route first, the status last) and publishes the event.
void keepOutcome(const ApproveWorkerOptions& o, NatsClient& nats, const std::string& op, const std::string& id, ApprovalBundle& bundle, const fs::path& dir,
                 const ApprovalOutcome& out) {
  const std::string key = op + "." + id;
  const bool has_report = fs::exists(dir / "out" / "report.json");
  if (has_report) {
    bundle.report = maps::readTextFile((dir / "out" / "report.json").string());
    nats.put(nats::kApprovalBucket, key + ".bundle", bundleText(bundle));
    if (fs::exists(dir / "out" / "route.geojson")) nats.put(nats::kApprovalBucket, key + ".route", maps::readTextFile((dir / "out" / "route.geojson").string()));
    keepOutputs(o, nats, key, dir / "out");
  }
  const std::string status = statusWord(out.exit_code, has_report);
  json st = {{"status", status}, {"operator", op}, {"id", id}};
  if (!out.message.empty()) st["message"] = out.message;
  nats.put(nats::kApprovalBucket, key, st.dump());
  st["event"] = "approval";
  (void)nats.publish(nats::eventSubject(op, id), st.dump(), "approval." + key);
}

void finishInvalid(NatsClient& nats, const std::string& op, const std::string& id, const std::string& why) {
  const std::string key = op + "." + id;
  json st = {{"status", "invalid"}, {"operator", op}, {"id", id}, {"message", why}};
  nats.put(nats::kApprovalBucket, key, st.dump());
  st["event"] = "approval";
  (void)nats.publish(nats::eventSubject(op, id), st.dump(), "approval." + key);
}

/// The mission's `zonesets` ("authority.NAME" or "<operator>.NAME") → their current versions as
/// files of the bundle, added to the mission's zones. \throws maps::ParseError naming the field.
void resolveZoneSets(NatsClient& nats, const std::string& op, ApprovalBundle& b, const std::string& source) {
  json m = maps::parseJsonText(b.mission, source + " mission");
  if (!m.is_object() || !m.contains("zonesets")) return;
  const json sets = m["zonesets"];
  if (!sets.is_array()) throw maps::ParseError(source, 0, "$.zonesets", "", "an array of zone set names");
  if (!m.contains("zones")) m["zones"] = json::array();
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::string field = "$.zonesets[" + std::to_string(i) + "]";
    const std::string name = sets[i].is_string() ? sets[i].get<std::string>() : std::string();
    const std::vector<std::string> t = nats::subjectTokens(name);
    if (t.size() != 2 || (t[0] != "authority" && t[0] != op) || !nats::validId(t[1])) {
      throw maps::ParseError(source, 0, field, name.substr(0, 64), "authority.NAME or " + op + ".NAME (a zone set of the authority or of this operator)");
    }
    const auto e = nats.get(nats::kZoneSetBucket, name);
    if (!e) throw maps::ParseError(source, 0, field, name, "a zone set put in " + nats::kZoneSetBucket + " (skylane nats zones)");
    const std::string file = "files/zs-" + name + ".json";
    b.files[file] = e->value;
    b.zonesets[name] = {file, e->revision};
    m["zones"].push_back(file);
  }
  m.erase("zonesets");
  b.mission = m.dump(1) + "\n";
}

bool finalStatus(NatsClient& nats, const std::string& key) {
  const auto e = nats.get(nats::kApprovalBucket, key);
  if (!e) return false;
  const std::string s = json::parse(e->value).value("status", "");
  return s != "queued" && s != "running";
}

void handleRequest(const ApproveWorkerOptions& o, NatsClient& nats, const NatsMessage& m, ApproveWorkerCounters& c) {
  const std::vector<std::string> t = nats::subjectTokens(m.subject);
  if (t.size() != 4 || !nats::validId(t[2]) || !nats::validId(t[3])) {
    json e = {{"event", "rejected_input"}, {"subject", m.subject}, {"error", "an approval request's subject is skylane.approve.<operator>.<id>"}};
    (void)nats.publish(nats::kRejectedSubject, e.dump(), "approve." + std::to_string(m.stream_seq));
    ++c.invalid;
    return NatsPull::ack(m);
  }
  const std::string &op = t[2], &id = t[3];
  if (finalStatus(nats, op + "." + id)) {
    ++c.repeats;
    return NatsPull::ack(m);
  }
  nats.put(nats::kApprovalBucket, op + "." + id, json{{"status", "running"}, {"operator", op}, {"id", id}, {"worker", o.name}}.dump());
  ApprovalBundle bundle;
  const fs::path dir = fs::path(o.work_dir) / op / id;
  try {
    bundle = parseBundle(m.data, m.subject);
    bundle.report.clear();
    bundle.zonesets.clear();
    resolveZoneSets(nats, op, bundle, m.subject);
    fs::remove_all(dir);
    unpackBundle(bundle, dir);
  } catch (const maps::ParseError& e) {
    finishInvalid(nats, op, id, e.what());
    ++c.invalid;
    return NatsPull::ack(m);
  }
  o.log(op + "/" + id + ": approving");
  const ApprovalOutcome out = runApproval(o, m, dir);
  keepOutcome(o, nats, op, id, bundle, dir, out);
  const std::string word = statusWord(out.exit_code, fs::exists(dir / "out" / "report.json"));
  o.log(op + "/" + id + ": " + word + (out.message.empty() ? "" : " — " + out.message));
  (word == "approved" ? c.approved : word == "rejected" ? c.rejected : word == "invalid" ? c.invalid : c.failed)++;
  NatsPull::ack(m);
}

/// The connection, waiting for a server that is not (yet) there.
std::unique_ptr<NatsClient> connectWaiting(const ApproveWorkerOptions& o, const std::atomic<bool>& stop) {
  for (int attempt = 0; !stop.load(); ++attempt) {
    try {
      auto nats = std::make_unique<NatsClient>(o.url, o.name);
      (void)nats::partitionCount(*nats);  // the streams are set up
      return nats;
    } catch (const NatsError& e) {
      if (o.log && attempt % 10 == 0) o.log(std::string("waiting for NATS: ") + e.what());
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
  return nullptr;
}

}  // namespace

void runApproveWorker(const ApproveWorkerOptions& o, const std::atomic<bool>& stop, ApproveWorkerCounters& c) {
  const std::unique_ptr<NatsClient> client = connectWaiting(o, stop);
  if (!client) return;
  NatsClient& nats = *client;
  std::unique_ptr<NatsPull> pull;
  while (!stop.load()) {
    try {
      if (!pull) pull = nats.pullShared(nats::kApprovalStream, "approvers", "skylane.approve.>", std::chrono::seconds(30));
      for (const NatsMessage& m : pull->fetch(1, std::chrono::milliseconds(500))) handleRequest(o, nats, m, c);
    } catch (const NatsError& e) {
      o.log(std::string("NATS: ") + e.what() + "; trying again");
      pull.reset();
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
}

}  // namespace skylane::service
