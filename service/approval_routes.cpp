/// \file
/// \brief Approvals: a mission submitted with its zone sets by id is written beside its outputs,
/// checked at once (a bad mission is a 400 naming the field), queued (429 with Retry-After when
/// the queue is full) and run by `skylane approve` on a worker; its status, progress, report,
/// route, operational intent, QGroundControl plan and pictures are then served.

#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"
#include "planner/mission.hpp"
#include "service/service_impl.hpp"

#include <algorithm>

namespace skylane::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// A request error: the 400 it becomes.
struct BadRequest {
  std::string message;
};

/// A message about a file of the service's own folder, with the folder left out (a caller
/// learns nothing of the server's paths).
std::string withoutFolder(std::string message, const fs::path& folder, const std::string& as) {
  const std::string f = folder.string();
  for (std::size_t at; (at = message.find(f)) != std::string::npos;) message.replace(at, f.size(), as);
  return message;
}

const std::map<std::string, std::string>& approvalFiles() {
  static const std::map<std::string, std::string> kFiles = {
      {"report.json", "application/json"},  {"route.geojson", "application/geo+json"},
      {"operational_intent.json", "application/json"}, {"mission.plan", "application/json"},
      {"map.svg", "image/svg+xml"},          {"pl.svg", "image/svg+xml"},
      {"mission.json", "application/json"}};
  return kFiles;
}

}  // namespace

json ServiceImpl::resolveMission(const json& body, const Principal& who, std::vector<std::string>* follow) {
  if (!body.is_object()) throw BadRequest{"the request body: expected a mission (a JSON object)"};
  if (body.contains("zones")) throw BadRequest{"$.zones: the service reads no files a request names; give zone sets by id in \"zonesets\""};
  if (body.contains("terrain")) throw BadRequest{"$.terrain: the service reads no files a request names; give ground_amsl_m"};
  if (body.contains("buildings")) throw BadRequest{"$.buildings: the service reads no files a request names; buildings are not served yet"};
  json m = body;
  json zones = json::array();
  const json sets = body.value("zonesets", json::array());
  if (!sets.is_array()) throw BadRequest{"$.zonesets: expected an array of zone set ids"};
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::string field = "$.zonesets[" + std::to_string(i) + "]";
    if (!sets[i].is_string()) throw BadRequest{field + ": expected a zone set id (\"zs-…\" or \"zs-…@version\")"};
    const std::string ref = sets[i].get<std::string>();
    const std::string id = ref.substr(0, ref.find('@'));
    LoadedZoneSet* z = visibleZoneSet(who, id);
    if (!z) throw BadRequest{field + ": no zone set \"" + id.substr(0, 64) + "\" you can use"};
    int version = z->set.latest().version;
    if (ref.find('@') != std::string::npos) {
      const std::string v = ref.substr(ref.find('@') + 1);
      const bool digits = !v.empty() && v.size() < 9 && std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!digits || std::stoi(v) < 1 || std::stoi(v) > version) {
        throw BadRequest{field + ": version \"" + v.substr(0, 16) + "\": expected 1 to " + std::to_string(version)};
      }
      version = std::stoi(v);
    }
    zones.push_back((files / z->set.versions[static_cast<std::size_t>(version - 1)].file).string());
    if (follow) follow->push_back(ref.find('@') == std::string::npos ? natsZoneSetKey(z->set) : std::string());
  }
  m.erase("zonesets");
  m["zones"] = zones;
  json orbits = json::array();
  if (body.contains("orbits")) {
    const json& names = body["orbits"];
    if (!names.is_array()) throw BadRequest{"$.orbits: expected an array of names of orbit files (GET /v1/orbits lists them)"};
    for (std::size_t i = 0; i < names.size(); ++i) {
      const std::optional<fs::path> p = names[i].is_string() ? orbitFile(who, names[i].get<std::string>()) : std::nullopt;
      if (!p) {
        throw BadRequest{"$.orbits[" + std::to_string(i) + "]: expected the name of an almanac or ephemeris file uploaded to /v1/orbits or of the "
                         "service's orbits folder (GET /v1/orbits lists them)"};
      }
      orbits.push_back(p->string());
    }
  } else {
    if (options.orbits_dir.empty()) throw BadRequest{"$.orbits: expected the names of orbit files (this service has no default orbits folder)"};
    std::vector<std::string> all;
    for (const auto& e : fs::directory_iterator(options.orbits_dir)) {
      if (e.is_regular_file() && e.path().filename().string().front() != '.') all.push_back(fs::absolute(e.path()).string());
    }
    std::sort(all.begin(), all.end());
    for (const std::string& p : all) orbits.push_back(p);
  }
  m["orbits"] = orbits;
  return m;
}

HttpResponse ServiceImpl::approvalsRoute(const HttpRequest& r, const Principal& who, const Segments& s) {
  if (s.size() == 2) {
    if (r.method == "POST") return submitApproval(r, who);
    if (r.method != "GET") return methodNotAllowed("GET, POST");
    json list = json::array();
    for (const auto& [id, a] : approvals) {
      if (a.row.owner == who.owner()) list.push_back({{"id", id}, {"name", a.row.name}, {"status", a.row.status}, {"created", a.row.created}});
    }
    return jsonBody(200, {{"approvals", list}});
  }
  const auto it = approvals.find(s[2]);
  if (it == approvals.end() || it->second.row.owner != who.owner()) return notFound("approval " + s[2]);
  if (r.method != "GET") return methodNotAllowed("GET");
  if (s.size() == 3) return approvalStatus(it->second);
  if (s.size() == 4) return approvalFile(it->second, s[3]);
  return notFound("route " + r.path);
}

HttpResponse ServiceImpl::submitApproval(const HttpRequest& r, const Principal& who) {
  if (who.authority) return errorResponse(403, "approvals are an operator's: the authority's token submits none");
  if (auto bad = requireContentType(r, {"application/json"})) return *bad;
  const std::string id = newId("ap-");
  const fs::path dir = files / "approvals" / id;
  std::string name;
  try {
    const json body = maps::parseJsonText(r.body, "the request body");
    std::vector<std::string> follow;
    const json mission = resolveMission(body, who, &follow);
    name = mission.value("name", json()).is_string() ? mission["name"].get<std::string>() : std::string();
    fs::create_directories(dir);
    writeFileAtomically(dir / "mission.json", mission.dump(1) + "\n");
    (void)planner::loadMission((dir / "mission.json").string());  // what approve will read, checked now
    if (nats) natsWriteMission(dir, mission, follow);
  } catch (const BadRequest& e) {
    return errorResponse(400, e.message);
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove_all(dir, ec);
    return errorResponse(400, withoutFolder(e.what(), dir / "mission.json", "the mission"));
  }
  ApprovalState a;
  a.row = {id, who.owner(), name, "queued", nowUtc(), "approvals/" + id, "", ""};
  a.submitted = std::chrono::steady_clock::now();
  if (nats) {
    try {
      nats->requestApproval(who.owner(), id, (dir / "nats_mission.json").string());
    } catch (const std::exception& e) {
      std::error_code ec;
      fs::remove_all(dir, ec);
      return errorResponse(503, withoutFolder(std::string("NATS: ") + e.what(), files, "the service folder"));
    }
  } else if (!pool->submit({id, (dir / "mission.json").string(), dir.string()})) {
    ++metrics.approvals_refused_queue_full;
    std::error_code ec;
    fs::remove_all(dir, ec);
    HttpResponse res = errorResponse(429, "the approval queue is full (" + std::to_string(pool->capacity()) + " waiting); try again later");
    res.headers.emplace_back("Retry-After", "5");
    return res;
  }
  ++metrics.approvals_submitted;
  store->putApproval(a.row);
  approvals[id] = std::move(a);
  HttpResponse res = jsonBody(202, {{"id", id}, {"status", "queued"}});
  res.headers.emplace_back("Location", "/v1/approvals/" + id);
  return res;
}

void ServiceImpl::queueApproval(ApprovalState& a) {
  const fs::path dir = files / a.row.dir;
  a.row.status = "queued";
  if (nats) {
    // The workers may have finished it while the service was down; else it is asked again (a
    // repeat within the queue's duplicate window is dropped, a worker never redoes a final one).
    if (natsTakeOutcome(a)) return;
    try {
      nats->requestApproval(a.row.owner, a.row.id, (dir / (fs::exists(dir / "nats_mission.json") ? "nats_mission.json" : "mission.json")).string());
    } catch (const std::exception& e) {
      a.row.status = "failed";
      a.row.error = withoutFolder(std::string("NATS: ") + e.what(), files, "the service folder");
    }
  } else if (!pool->submit({a.row.id, (dir / "mission.json").string(), dir.string()})) {
    a.row.status = "failed";
    a.row.error = "the approval queue was full when the service restarted";
  }
  store->putApproval(a.row);
}

void ServiceImpl::approvalDone(const std::string& id, const ApprovalOutcome& outcome) {
  const auto it = approvals.find(id);
  if (it == approvals.end()) return;
  ApprovalState& a = it->second;
  const bool has_report = fs::exists(files / a.row.dir / "report.json");
  if (outcome.exit_code == 0 && has_report) {
    a.row.status = "approved";
  } else if (outcome.exit_code == 1 && has_report && outcome.message.empty()) {
    a.row.status = "rejected";
  } else {
    a.row.status = "failed";
    a.row.error = withoutFolder(outcome.message.empty() ? "the approval ended without a report (exit " + std::to_string(outcome.exit_code) + ")"
                                                        : outcome.message,
                                files / a.row.dir / "mission.json", "the mission");
    a.row.error = withoutFolder(a.row.error, files, "the service folder");
  }
  if (!a.progress.empty()) a.row.summary = a.progress.back();
  metrics.approval_seconds.observe(std::chrono::duration<double>(std::chrono::steady_clock::now() - a.submitted).count());
  store->putApproval(a.row);
  log("approval " + id + ": " + a.row.status + (a.row.error.empty() ? "" : " (" + a.row.error + ")"));
}

HttpResponse ServiceImpl::approvalStatus(const ApprovalState& a) const {
  json j = {{"id", a.row.id}, {"name", a.row.name}, {"status", a.row.status}, {"created", a.row.created}, {"progress", a.progress}};
  if (!a.row.summary.empty()) j["summary"] = a.row.summary;
  if (!a.row.error.empty()) j["error"] = a.row.error;
  if (a.row.status == "approved" || a.row.status == "rejected") {
    json links = json::object();
    for (const auto& [name, type] : approvalFiles()) {
      if (fs::exists(files / a.row.dir / name)) links[name] = "/v1/approvals/" + a.row.id + "/" + name;
    }
    j["files"] = links;
  }
  return jsonBody(200, j);
}

HttpResponse ServiceImpl::approvalFile(const ApprovalState& a, const std::string& name) const {
  const auto it = approvalFiles().find(name);
  if (it == approvalFiles().end()) return notFound("file " + name + " of an approval");
  if (a.row.status == "queued" || a.row.status == "running") return errorResponse(409, "approval " + a.row.id + " is " + a.row.status + ": no " + name + " yet");
  return fileResponse(files / a.row.dir / name, it->second);
}

}  // namespace skylane::service
