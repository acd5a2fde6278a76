#include "cli/worker_commands.hpp"

#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "cli/zones_commands.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "planner/mission.hpp"
#include "service/approval_bundle.hpp"
#include "service/approve_worker.hpp"
#include "service/nats_layout.hpp"
#include "service/track_worker.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include <unistd.h>

namespace skylane::cli {

namespace {

using nlohmann::json;
namespace nats = service::nats;

std::atomic<bool> g_stop{false};
void onSignal(int) { g_stop.store(true); }

/// The client, with a failure to connect named by the option (the caller's to fix: exit 2).
std::unique_ptr<service::NatsClient> connect(const std::string& url, const std::string& name) {
  try {
    return std::make_unique<service::NatsClient>(url, name);
  } catch (const service::NatsError& e) {
    throw std::invalid_argument("--nats " + url + ": " + e.what());
  }
}

std::string selfExecutable() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find the skylane executable (/proc/self/exe)");
  return std::string(buf, static_cast<std::size_t>(n));
}

/// "all", "3", "0,2,5" or "0-3" → the partitions (empty: all).
std::vector<int> parsePartitions(const std::string& spec) {
  std::vector<int> out;
  if (spec.empty() || spec == "all") return out;
  std::stringstream ss(spec);
  for (std::string part; std::getline(ss, part, ',');) {
    const std::size_t dash = part.find('-');
    try {
      std::size_t used = 0;
      const int a = std::stoi(part.substr(0, dash), &used);
      const int b = dash == std::string::npos ? a : std::stoi(part.substr(dash + 1));
      if (a < 0 || b < a || b > 1023) throw std::out_of_range(part);
      for (int k = a; k <= b; ++k) out.push_back(k);
    } catch (const std::logic_error&) {
      throw maps::ParseError("--partitions", 0, "--partitions", spec, "all, a partition, a list 0,2,5 or a range 0-3 (0 to 1023)");
    }
  }
  return out;
}

struct WorkerCli {
  std::string url = "nats://127.0.0.1:4222", role, partitions = "all", cache, work, name;
  bool quiet = false;
};

void runWorker(const WorkerCli& w) {
  const std::string name = w.name.empty() ? w.role + "-" + std::to_string(getpid()) : w.name;
  auto log = [quiet = w.quiet, name](const std::string& m) {
    if (!quiet) std::cerr << "skylane: worker " << name << ": " << m << std::endl;
  };
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGPIPE, SIG_IGN);
  const std::string tmp = std::filesystem::temp_directory_path().string();
  try {
    if (w.role == "track") {
      service::TrackWorkerOptions o{w.url, name, parsePartitions(w.partitions), w.cache.empty() ? tmp + "/skylane-worker-cache" : w.cache, {}, 512, log};
      service::TrackWorkerCounters c;
      service::runTrackWorker(o, g_stop, c);
    } else {
      service::ApproveWorkerOptions o{w.url, name, selfExecutable(), w.work.empty() ? tmp + "/skylane-approvals-" + name : w.work, log};
      service::ApproveWorkerCounters c;
      service::runApproveWorker(o, g_stop, c);
    }
  } catch (const service::NatsError& e) {
    throw std::invalid_argument("--nats " + w.url + ": " + e.what());
  }
  log("stopped");
}

void addWorker(CLI::App& app) {
  auto w = std::make_shared<WorkerCli>();
  CLI::App* c = app.add_subcommand("worker", "a NATS JetStream worker: tracks its partitions of the fix stream, or takes approvals from the queue");
  c->add_option("--nats", w->url, "NATS server URL(s), comma-separated (default nats://127.0.0.1:4222)");
  c->add_option("--role", w->role, "track or approve")->required()->check(CLI::IsMember({"track", "approve"}));
  c->add_option("--partitions", w->partitions, "track: the partitions it may hold (all, 3, 0,2,5 or 0-3; default all)");
  c->add_option("--cache", w->cache, "track: folder for the approvals' bundles (default TMPDIR/skylane-worker-cache)");
  c->add_option("--work", w->work, "approve: folder the approvals run in (default TMPDIR/skylane-approvals-NAME)");
  c->add_option("--name", w->name, "the worker's name in leases and logs (default ROLE-PID)");
  c->add_flag("--quiet", w->quiet, "no log lines on stderr");
  c->callback([w] { runWorker(*w); });
}

struct NatsCli {
  std::string url = "nats://127.0.0.1:4222", op, id, flight, approval, file;
  int partitions = 8;
  double wait_s = 0;
  std::uint64_t from = 1;
};

void requireId(const std::string& value, const char* option) {
  if (!nats::validId(value)) throw maps::ParseError(option, 0, option, value, "1 to 64 of A-Z a-z 0-9 - _, not starting with _");
}

void runSetup(const NatsCli& n) {
  auto c = connect(n.url, "skylane-setup");
  nats::setUp(*c, n.partitions);
  std::cout << "# skylane's streams and buckets are ready for " << n.partitions << " partitions; the server's configuration needs:\n"
            << nats::serverMappings(n.partitions);
}

/// The mission as `skylane approve` will read it (its `zonesets`, resolved by the approve
/// worker, left out): a bad one is the client's error at once, not an invalid approval later.
void checkMission(const std::string& path) {
  nlohmann::json doc = maps::readJsonFile(path);
  if (doc.is_object()) doc.erase("zonesets");
  (void)planner::parseMission(doc, path, std::filesystem::path(path).parent_path().string());
}

/// Publishes an approval request; with --wait, its outcome (exit 0 approved, 1 rejected or failed, 2 invalid).
void runApprove(const NatsCli& n) {
  requireId(n.op, "--operator");
  requireId(n.id, "--id");
  checkMission(n.file);
  const service::ApprovalBundle b = service::packMission(n.file);
  auto c = connect(n.url, "skylane-approve");
  (void)c->publish(nats::approvalSubject(n.op, n.id), service::bundleText(b), "request." + n.op + "." + n.id);
  if (n.wait_s <= 0) return;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(n.wait_s);
  while (std::chrono::steady_clock::now() < until) {
    if (const auto e = c->get(nats::kApprovalBucket, n.op + "." + n.id)) {
      const json st = json::parse(e->value);
      const std::string s = st.value("status", "");
      if (s != "running" && s != "queued") {
        std::cout << st.dump() << std::endl;
        throw ExitStatus{s == "approved" ? 0 : s == "invalid" ? 2 : 1};
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  throw std::runtime_error("no outcome of approval " + n.op + "/" + n.id + " within --wait " + std::to_string(n.wait_s) + " s");
}

/// Validates a zone file and puts it as a new version of zone set OWNER.NAME; prints the version.
void runZones(const NatsCli& n) {
  if (n.op != "authority") requireId(n.op, "--owner");
  requireId(n.id, "--set");
  const std::string text = maps::readTextFile(n.file);
  std::vector<airspace::Zone> zones = airspace::parseZones(maps::parseJsonText(text, n.file), n.file);
  const airspace::ValidationReport report = airspace::validateZones(zones, false);
  if (const airspace::ZoneIssue* e = report.firstError()) throw maps::ParseError(n.file, 0, zones[e->zone].feature, "", e->what + "; expected a valid zone");
  if (zones.empty()) throw maps::ParseError(n.file, 0, "$", "", "at least one zone");
  auto c = connect(n.url, "skylane-zones");
  const std::uint64_t version = c->put(nats::kZoneSetBucket, n.op + "." + n.id, text);
  std::cout << json{{"zoneset", n.op + "." + n.id}, {"version", version}, {"zones", zones.size()}}.dump() << std::endl;
}

/// Publishes a start record (with --approval) and then every line of the file as a fix.
void runPublish(const NatsCli& n) {
  requireId(n.op, "--operator");
  requireId(n.flight, "--flight");
  if (!n.approval.empty()) requireId(n.approval, "--approval");
  std::ifstream file;
  if (n.file != "-") {
    maps::requireNotAFolder(n.file, "FIXES");
    file.open(n.file);
    if (!file) throw maps::ParseError(n.file, 0, "FIXES", n.file, "a readable file of JSON lines");
  }
  std::istream& in = n.file == "-" ? std::cin : file;
  auto c = connect(n.url, "skylane-publish");
  const std::string subject = nats::fixSubject(n.op, n.flight);
  std::size_t count = 0;
  if (!n.approval.empty()) c->publishAsync(subject, json{{"start", {{"approval", n.approval}}}}.dump());
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    c->publishAsync(subject, line);
    ++count;
  }
  c->publishesComplete(std::chrono::seconds(60));
  std::cerr << "skylane: published " << count << " fixes to " << subject << "\n";
}

/// The event stream from --from, filtered, as JSON lines; ends when caught up.
void runEvents(const NatsCli& n) {
  auto c = connect(n.url, "skylane-events");
  const std::string want = "skylane.event." + (n.op.empty() ? std::string() : n.op + ".") + (n.flight.empty() ? std::string() : n.flight);
  const std::uint64_t last = c->lastSequence(nats::kEventStream);
  for (std::uint64_t s = std::max<std::uint64_t>(n.from, 1); s <= last; ++s) {
    const auto m = c->message(nats::kEventStream, s);
    if (!m || m->subject.rfind(want, 0) != 0) continue;
    if (!n.flight.empty() && m->subject.size() != want.size()) continue;
    std::cout << m->data << "\n";
  }
}

void addNats(CLI::App& app) {
  auto n = std::make_shared<NatsCli>();
  CLI::App* top = app.add_subcommand("nats", "skylane on NATS JetStream: set up, request approvals, publish fixes, read events");
  top->require_subcommand(1);
  auto url = [n](CLI::App* c) { c->add_option("--nats", n->url, "NATS server URL(s) (default nats://127.0.0.1:4222)"); };
  CLI::App* setup = top->add_subcommand("setup", "make the streams and buckets; print the server's subject mapping");
  url(setup);
  setup->add_option("--partitions", n->partitions, "fix partitions (default 8)")->check(CLI::Range(1, 1024));
  setup->callback([n] { runSetup(*n); });
  CLI::App* approve = top->add_subcommand("approve", "request the approval of a mission (with its files) from the approve workers");
  url(approve);
  approve->add_option("MISSION", n->file, "mission file")->required();
  approve->add_option("--operator", n->op, "operator id")->required();
  approve->add_option("--id", n->id, "approval id (unique per operator)")->required();
  approve->add_option("--wait", n->wait_s, "seconds to wait for the outcome, printed (exit 0 approved, 1 rejected, 2 invalid)");
  approve->callback([n] { runApprove(*n); });
  CLI::App* zones = top->add_subcommand("zones", "put a zone file (ED-269, ED-318, GeoJSON, QGC) as the next version of a zone set");
  url(zones);
  zones->add_option("ZONES", n->file, "zone file")->required()->check(CLI::ExistingFile);
  zones->add_option("--owner", n->op, "authority, or the operator whose private set it is")->required();
  zones->add_option("--set", n->id, "the zone set's name")->required();
  zones->callback([n] { runZones(*n); });
  CLI::App* publish = top->add_subcommand("publish", "publish a flight's fixes (JSON lines) to skylane.fix.OPERATOR.FLIGHT");
  url(publish);
  publish->add_option("FIXES", n->file, "file of JSON lines, - for standard input")->required();
  publish->add_option("--operator", n->op, "operator id")->required();
  publish->add_option("--flight", n->flight, "flight id")->required();
  publish->add_option("--approval", n->approval, "start the flight from this approval first");
  publish->callback([n] { runPublish(*n); });
  CLI::App* events = top->add_subcommand("events", "print the events (JSON lines) from a sequence on, up to the last");
  url(events);
  events->add_option("--operator", n->op, "only this operator's");
  events->add_option("--flight", n->flight, "only this flight's (with --operator)");
  events->add_option("--from", n->from, "first event stream sequence (default 1)");
  events->callback([n] { runEvents(*n); });
}

}  // namespace

void addWorkerCommands(CLI::App& app) {
  addWorker(app);
  addNats(app);
}

}  // namespace skylane::cli
