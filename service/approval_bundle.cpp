#include "service/approval_bundle.hpp"

#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

namespace skylane::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// Replaces a file name in the mission by a bundle-relative one and carries the file.
std::string carry(const std::string& name, const fs::path& base, ApprovalBundle& b) {
  fs::path p(name);
  if (p.is_relative()) p = base / p;
  const std::string rel = "files/" + std::to_string(b.files.size()) + "-" + p.filename().string();
  b.files[rel] = maps::readTextFile(p.lexically_normal().string());
  return rel;
}

void carryArray(json& m, const char* key, const fs::path& base, ApprovalBundle& b, const std::string& mission_path) {
  if (!m.contains(key)) return;
  if (!m[key].is_array()) throw maps::ParseError(mission_path, 0, std::string("$.") + key, m[key].dump().substr(0, 64), "an array of file names");
  for (auto& v : m[key]) {
    if (!v.is_string()) throw maps::ParseError(mission_path, 0, std::string("$.") + key, v.dump().substr(0, 64), "a file name");
    v = carry(v.get<std::string>(), base, b);
  }
}

/// A bundle's file name: relative, no `..`, no empty or dot parts.
bool safeRelativeName(const std::string& name) {
  if (name.empty() || name.size() > 200 || name.front() == '/') return false;
  for (const auto& part : fs::path(name)) {
    const std::string s = part.string();
    if (s.empty() || s == "." || s == "..") return false;
  }
  return name.find('\\') == std::string::npos && name.find('\0') == std::string::npos;
}

}  // namespace

ApprovalBundle packMission(const std::string& mission_path) {
  json m = maps::readJsonFile(mission_path);
  if (!m.is_object()) throw maps::ParseError(mission_path, 0, "$", "", "a mission object");
  if (m.contains("terrain")) {
    throw maps::ParseError(mission_path, 0, "$.terrain", m["terrain"].dump().substr(0, 64),
                           "ground_amsl_m instead (a terrain raster is not carried to the workers)");
  }
  const fs::path base = fs::path(mission_path).parent_path();
  ApprovalBundle b;
  carryArray(m, "zones", base, b, mission_path);
  carryArray(m, "orbits", base, b, mission_path);
  for (const char* key : {"buildings", "qgc_plan"}) {
    if (!m.contains(key)) continue;
    if (!m[key].is_string()) throw maps::ParseError(mission_path, 0, std::string("$.") + key, m[key].dump().substr(0, 64), "a file name");
    m[key] = carry(m[key].get<std::string>(), base, b);
  }
  b.mission = m.dump(1) + "\n";
  return b;
}

json zoneSetsJson(const std::map<std::string, ApprovalBundle::ZoneSetFile>& sets) {
  json z = json::object();
  for (const auto& [name, f] : sets) z[name] = {{"file", f.file}, {"version", f.version}};
  return z;
}

std::string zoneSetsText(const std::map<std::string, ApprovalBundle::ZoneSetFile>& sets) { return zoneSetsJson(sets).dump(); }

std::string bundleText(const ApprovalBundle& b) {
  json j = {{"mission", b.mission}, {"files", b.files}};
  if (!b.zonesets.empty()) j["zonesets"] = zoneSetsJson(b.zonesets);
  if (!b.report.empty()) j["report"] = b.report;
  return j.dump();
}

namespace {

std::map<std::string, ApprovalBundle::ZoneSetFile> parseZoneSets(const json& z, const std::string& source) {
  std::map<std::string, ApprovalBundle::ZoneSetFile> out;
  if (!z.is_object()) throw maps::ParseError(source, 0, "$.zonesets", "", "an object of zone set name → {file, version}");
  for (const auto& [name, f] : z.items()) {
    const bool ok = f.is_object() && f.contains("file") && f["file"].is_string() && safeRelativeName(f["file"].get<std::string>()) &&
                    f.contains("version") && f["version"].is_number_unsigned();
    if (!ok) throw maps::ParseError(source, 0, "$.zonesets." + name.substr(0, 64), "", "{\"file\": a relative name, \"version\": a revision}");
    out[name] = {f["file"].get<std::string>(), f["version"].get<std::uint64_t>()};
  }
  return out;
}

}  // namespace

std::map<std::string, ApprovalBundle::ZoneSetFile> readZoneSets(const fs::path& dir) {
  if (!fs::exists(dir / "zonesets.json")) return {};
  return parseZoneSets(maps::readJsonFile((dir / "zonesets.json").string()), (dir / "zonesets.json").string());
}

ApprovalBundle parseBundle(const std::string& text, const std::string& source) {
  const json j = maps::parseJsonText(text, source);
  if (!j.is_object() || !j.contains("mission") || !j["mission"].is_string()) {
    throw maps::ParseError(source, 0, "$.mission", "", "the mission file's text (a string)");
  }
  ApprovalBundle b;
  b.mission = j["mission"].get<std::string>();
  if (j.contains("files")) {
    if (!j["files"].is_object()) throw maps::ParseError(source, 0, "$.files", "", "an object of file name → text");
    for (const auto& [name, content] : j["files"].items()) {
      if (!safeRelativeName(name)) throw maps::ParseError(source, 0, "$.files", name.substr(0, 64), "a relative file name without ..");
      if (!content.is_string()) throw maps::ParseError(source, 0, "$.files." + name.substr(0, 64), "", "the file's text");
      b.files[name] = content.get<std::string>();
    }
  }
  if (j.contains("zonesets")) b.zonesets = parseZoneSets(j["zonesets"], source);
  if (j.contains("report")) {
    if (!j["report"].is_string()) throw maps::ParseError(source, 0, "$.report", "", "the report's text");
    b.report = j["report"].get<std::string>();
  }
  return b;
}

void unpackBundle(const ApprovalBundle& b, const fs::path& dir) {
  fs::create_directories(dir);
  for (const auto& [name, content] : b.files) {
    const fs::path p = dir / name;
    fs::create_directories(p.parent_path());
    maps::writeFileAtomically(p.string(), content, "bundle file");
  }
  maps::writeFileAtomically((dir / "mission.json").string(), b.mission, "bundle mission");
  if (!b.zonesets.empty()) maps::writeFileAtomically((dir / "zonesets.json").string(), zoneSetsText(b.zonesets) + "\n", "bundle zone sets");
  if (!b.report.empty()) maps::writeFileAtomically((dir / "report.json").string(), b.report, "bundle report");
}

}  // namespace skylane::service
