#include "geofence/verdict_json.hpp"

#include "maps/json_node.hpp"
#include "maps/json_numbers.hpp"

#include <limits>

namespace skylane::geofence {

using nlohmann::json;

void to_json(json& j, const Check& c) {
  j = json::object();
  j["level"] = levelName(c.level);
  j["verdict"] = verdictWord(c.level, c.verdict);
  j["subject"] = c.subject;
  j["margin_h_m"] = maps::metresOrNull(c.margin_h_m);
  j["margin_v_m"] = maps::metresOrNull(c.margin_v_m);
  if (c.level == Level::kZone || c.level == Level::kKeepIn) {
    j["name"] = c.name;
    j["restriction"] = c.restriction;
  }
  if (isBoxLevel(c)) {
    j["segment"] = c.index;
    j["across_joint"] = c.across_joint;
  } else if (c.level != Level::kKeepIn) {
    j["clearance_m"] = c.clearance_m ? maps::metresOrNull(*c.clearance_m) : json(nullptr);
    j["exact"] = c.exact;
  }
}

void to_json(json& j, const FenceVerdict& v) {
  j = json::object();
  j["verdict"] = verdictName(v.verdict);
  j["violated"] = v.violated ? json(levelName(*v.violated)) : json(nullptr);
  j["checks"] = v.checks;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const std::string kSource = "fence verdict";

Level levelOf(const maps::JsonNode& n) {
  const std::string s = n.str();
  for (Level l : {Level::kCorridor, Level::kAirspace, Level::kKeepIn, Level::kZone, Level::kObstacle}) {
    if (s == levelName(l)) return l;
  }
  n.fail("level1, level2, keep_in, zone or obstacle");
}

/// The verdict word of a check of `level` (verdictWord).
Verdict verdictOf(const maps::JsonNode& n, Level level) {
  const std::string s = n.str();
  for (Verdict v : {Verdict::kInside, Verdict::kOutside, Verdict::kIndeterminate}) {
    if (s == verdictWord(level, v)) return v;
  }
  n.fail(isContainmentLevel(level) ? "inside, outside or indeterminate" : "clear, met or indeterminate");
}

/// The verdict of a whole volume: inside (the allowed space), outside or indeterminate.
Verdict verdictOf(const maps::JsonNode& n) { return verdictOf(n, Level::kCorridor); }

/// A length of the one form: a number, or null for an unlimited one (the member must be there).
double metresOf(const maps::JsonNode& n, const char* key) {
  if (!n.j.contains(key)) (void)n.at(key);  // names the missing member
  const maps::JsonNode v{n.j.at(key), n.path + "." + key, n.source};
  return v.j.is_null() ? kInf : v.number();
}

Check checkOf(const maps::JsonNode& n) {
  Check c;
  c.level = levelOf(n.at("level"));
  c.verdict = verdictOf(n.at("verdict"), c.level);
  c.subject = n.at("subject").str();
  if (c.level == Level::kZone || c.level == Level::kKeepIn) {
    if (n.has("name")) c.name = n.at("name").str();
    if (n.has("restriction")) c.restriction = n.at("restriction").str();
  }
  c.margin_h_m = metresOf(n, "margin_h_m");
  c.margin_v_m = metresOf(n, "margin_v_m");
  if (isBoxLevel(c)) {
    const double segment = n.at("segment").number();
    if (!(segment >= 0.0) || segment != static_cast<double>(static_cast<std::size_t>(segment))) n.at("segment").fail("a segment index ≥ 0");
    c.index = static_cast<std::size_t>(segment);
    c.across_joint = n.at("across_joint").boolean();
  } else if (c.level != Level::kKeepIn) {
    if (n.has("clearance_m")) c.clearance_m = n.at("clearance_m").number();
    c.exact = n.at("exact").boolean();
  }
  return c;
}

}  // namespace

void from_json(const json& j, Check& c) {
  if (!j.is_object()) maps::JsonNode{j, "$", kSource}.fail("a check object");
  c = checkOf(maps::JsonNode{j, "$", kSource});
}

void from_json(const json& j, FenceVerdict& v) {
  const maps::JsonNode root{j, "$", kSource};
  if (!j.is_object()) root.fail("a verdict object");
  v = FenceVerdict{};
  v.verdict = verdictOf(root.at("verdict"));
  if (root.has("violated")) v.violated = levelOf(root.at("violated"));
  const maps::JsonNode checks = root.at("checks");
  for (std::size_t i = 0; i < checks.array().size(); ++i) {
    const maps::JsonNode c = checks.item(i);
    if (!c.j.is_object()) c.fail("a check object");
    v.checks.push_back(checkOf(c));
    // The deciding check: the first of the violated level with the verdict's outcome.
    const Check& last = v.checks.back();
    if (!v.deciding && v.violated && last.level == *v.violated && last.verdict == v.verdict) v.deciding = i;
  }
  if (v.violated && !v.deciding) root.at("violated").fail("a level with a check of the verdict's outcome");
}

json fenceVerdictJson(const FenceVerdict& v, const Fence& fence) {
  json out = v;  // the one form, with what the fence knows of each check
  for (std::size_t i = 0; i < v.checks.size(); ++i) {
    const Check& c = v.checks[i];
    json& j = out["checks"][i];
    if (isBoxLevel(c)) {
      const AlertLimits& l = (c.level == Level::kCorridor ? fence.level1() : fence.level2()).limits();
      j["hal_m"] = maps::metresOrNull(l.hal_m);
      j["val_m"] = maps::metresOrNull(l.val_m);
    } else if (c.level == Level::kZone || c.level == Level::kKeepIn) {
      j["file"] = fence.zones()[c.index].source;
    }
  }
  return out;
}

json pickMembers(const json& object, std::initializer_list<const char*> keys) {
  json out = json::object();
  for (const char* k : keys) {
    const auto it = object.find(k);
    if (it != object.end()) out[k] = *it;
  }
  return out;
}

}  // namespace skylane::geofence
