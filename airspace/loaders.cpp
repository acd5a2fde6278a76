#include "airspace/loaders.hpp"

#include "airspace/applicability.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

namespace skylane::airspace {
namespace {

using nlohmann::json;
using maps::ParseError;
using maps::quoteJson;
using Node = maps::JsonNode;

/// The member's text when it is a string, "" otherwise (absent, a number, an array …).
std::string stringMember(const json& doc, const char* key) {
  const auto it = doc.find(key);
  return it != doc.end() && it->is_string() ? it->get<std::string>() : std::string();
}

/// ED-318 writes 99999 (in the layer's unit) for "no upper limit".
constexpr double kEd318Unlimited = 99999.0;

/// A string, or the en-GB (else first) text of an ED-318 [{text, lang}] list.
std::string text(const Node& n) {
  if (n.j.is_string()) return n.j.get<std::string>();
  if (!n.j.is_array()) n.fail("a string or a list of {text, lang}");
  std::string first;
  for (std::size_t i = 0; i < n.j.size(); ++i) {
    const Node entry = n.item(i);
    const std::string t = entry.at("text").str();
    const std::string lang = entry.has("lang") ? entry.at("lang").str() : "";
    if (lang == "en-GB" || lang == "en") return t;
    if (i == 0) first = t;
  }
  return first;
}

std::string optionalText(const Node& n, const char* key) { return n.has(key) ? text(n.at(key)) : std::string(); }

std::vector<std::string> stringList(const Node& n) {
  std::vector<std::string> out;
  if (n.j.is_string()) return {n.j.get<std::string>()};
  const json& a = n.array();
  for (std::size_t i = 0; i < a.size(); ++i) out.push_back(n.item(i).str());
  return out;
}

/// [lon, lat] (GeoJSON order) or [lat, lon] (QGroundControl) in degrees → LatLon.
LatLon position(const Node& n, bool lat_first) {
  const json& a = n.array();
  if (a.size() < 2) n.fail(lat_first ? "[lat, lon] in degrees" : "[lon, lat] in degrees");
  const double lon = n.item(lat_first ? 1 : 0).number();
  const double lat = n.item(lat_first ? 0 : 1).number();
  if (!(lat >= -90.0 && lat <= 90.0)) n.item(lat_first ? 0 : 1).fail("a latitude in [-90, 90] degrees");
  if (!(lon >= -180.0 && lon <= 180.0)) n.item(lat_first ? 1 : 0).fail("a longitude in [-180, 180] degrees");
  return {maps::deg2rad(lat), maps::deg2rad(lon)};
}

std::vector<LatLon> ring(const Node& n, bool lat_first) {
  const json& a = n.array();
  std::vector<LatLon> out;
  out.reserve(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out.push_back(position(n.item(i), lat_first));
  return out;
}

/// GeoJSON Polygon coordinates: one outer ring; holes are not part of the zone model.
Outline polygonOutline(const Node& coordinates) {
  const json& rings = coordinates.array();
  if (rings.empty()) coordinates.fail("a list of linear rings");
  if (rings.size() > 1) {
    coordinates.item(1).fail("no interior rings (zones with holes are not supported: split the zone)");
  }
  Outline o;
  o.kind = Outline::Kind::kPolygon;
  o.ring = ring(coordinates.item(0), /*lat_first=*/false);
  return o;
}

Outline circleOutline(const LatLon& centre, const Node& radius, double metres_per_unit) {
  const double r = radius.number() * metres_per_unit;
  if (!(r > 0.0)) radius.fail("a positive radius");
  Outline o;
  o.kind = Outline::Kind::kCircle;
  o.centre = centre;
  o.radius_m = r;
  return o;
}

VerticalReference reference(const Node& n) {
  const std::string t = n.str();
  if (t == "AGL" || t == "SFC") return VerticalReference::kAgl;
  if (t == "AMSL" || t == "MSL") return VerticalReference::kAmsl;
  if (t == "WGS84" || t == "W84") return VerticalReference::kWgs84;
  n.fail("AGL, AMSL or WGS84");
}

/// Metres per unit for "M"/"m" and "FT"/"ft".
double unitScale(const Node& n) {
  const std::string t = n.str();
  if (t == "M" || t == "m") return 1.0;
  if (t == "FT" || t == "ft") return kMetresPerFoot;
  n.fail("M or FT");
}

std::string unitName(double scale) { return scale == 1.0 ? "M" : "FT"; }

std::string formatNumber(double v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

/// A limit given as a number, a numeric string or null (= unlimited).
VerticalLimit limit(const Node& value, VerticalReference ref, double scale, bool ceiling,
                    double unlimited_value = std::numeric_limits<double>::infinity()) {
  VerticalLimit l;
  l.reference = ref;
  if (value.j.is_null()) {
    l.unlimited = true;
    l.as_given = ceiling ? "unlimited" : "no floor";
    return l;
  }
  double v = 0.0;
  if (value.j.is_string()) {
    const std::string t = value.j.get<std::string>();
    char* end = nullptr;
    v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v)) value.fail("a number, a numeric string or null");
  } else {
    v = value.number();
  }
  if (ceiling && v >= unlimited_value) {
    l.unlimited = true;
    l.as_given = formatNumber(v) + " " + unitName(scale) + " (unlimited)";
    return l;
  }
  l.value_m = v * scale;
  l.as_given = formatNumber(v) + " " + unitName(scale) + " " + std::string(referenceName(ref));
  return l;
}

std::optional<maps::GpsTime> dateTime(const Node& parent, const char* key) {
  if (!parent.has(key)) return std::nullopt;
  const Node n = parent.at(key);
  const auto t = maps::parseRfc3339(n.str());
  if (!t) n.fail("an RFC 3339 date-time such as 2026-06-15T09:00:00Z");
  return t;
}

/// A daily period: {day: [...], startTime|startEvent, endTime|endEvent}; nulls mean whole day.
DailyPeriod dailyPeriod(const Node& n, Zone& zone) {
  DailyPeriod p;
  if (n.has("day")) {
    const Node days = n.at("day");
    unsigned mask = 0;
    const json& a = days.array();
    for (std::size_t i = 0; i < a.size(); ++i) {
      const auto m = weekdayMask(days.item(i).str());
      if (!m) days.item(i).fail("MON, TUE, WED, THU, FRI, SAT, SUN or ANY");
      mask |= *m;
    }
    p.days = mask == 0 ? 0x7fu : mask;  // an empty list: every day
  }
  const auto time = [&](const char* key, const char* event_key, double whole_day_value) {
    if (n.has(key)) {
      const Node t = n.at(key);
      const std::string text = t.str();
      const auto s = parseTimeOfDay(text);
      if (!s) t.fail("a time of day HH:MM[:SS[.ff]] with Z or an offset, such as 17:00:00.00Z");
      return *s;
    }
    if (n.has(event_key)) {
      p.approximated = true;
      zone.notes.push_back(n.path + "." + event_key + " '" + quoteJson(n.at(event_key).j) +
                           "' (sunrise/sunset event) taken as the whole day, on the safe side");
    }
    return whole_day_value;
  };
  p.start_s = time("startTime", "startEvent", 0.0);
  p.end_s = time("endTime", "endEvent", 86400.0);
  if (p.approximated) {
    p.start_s = 0.0;
    p.end_s = 86400.0;
  }
  // "23:59:59" is how files write "until midnight": extend to the end of the day (safe side).
  if (n.has("endTime")) {
    const double day_fraction = std::fmod(p.end_s + 86400.0 * 3, 86400.0);
    if (day_fraction >= 86399.0) p.end_s += 86400.0 - day_fraction;
  }
  return p;
}

std::vector<DailyPeriod> schedule(const Node& entry, Zone& zone) {
  std::vector<DailyPeriod> out;
  for (const char* key : {"schedule", "dailyPeriod"}) {
    if (!entry.has(key)) continue;
    const Node list = entry.at(key);
    const json& a = list.array();
    for (std::size_t i = 0; i < a.size(); ++i) out.push_back(dailyPeriod(list.item(i), zone));
  }
  return out;
}

/// ED-269 `applicability` / ED-318 `limitedApplicability` entry.
Applicability applicability(const Node& n, Zone& zone, bool ed269) {
  Applicability a;
  a.permanent = false;  // ED-318 limitedApplicability entries are limited by definition
  if (ed269 && n.has("permanent")) {
    const std::string p = n.at("permanent").str();
    if (p != "YES" && p != "NO") n.at("permanent").fail("YES or NO");
    a.permanent = p == "YES";
  }
  a.start = dateTime(n, "startDateTime");
  a.end = dateTime(n, "endDateTime");
  if (a.start && a.end && !(*a.end - *a.start > 0.0)) n.at("endDateTime").fail("a date-time after startDateTime");
  a.schedule = schedule(n, zone);
  if (!a.permanent && !a.start && !a.end && a.schedule.empty()) a.permanent = true;  // nothing limits it
  return a;
}

std::string featureLabel(const std::string& path, const Zone& z) {
  return z.identifier.empty() ? path : path + "(" + z.identifier + ")";
}

// --- ED-269 ---------------------------------------------------------------

Zone ed269Zone(const Node& n) {
  Zone z;
  z.source = n.source;
  z.identifier = n.has("identifier") ? n.at("identifier").str() : "";
  z.feature = featureLabel(n.path, z);
  const Node f{n.j, z.feature, n.source};
  z.name = optionalText(f, "name");
  z.country = optionalText(f, "country");
  const Node r = f.at("restriction");
  const auto restriction = parseRestriction(r.str());
  if (!restriction) r.fail("PROHIBITED, REQ_AUTHORISATION, CONDITIONAL or NO_RESTRICTION");
  z.restriction = *restriction;
  if (f.has("reason")) z.reasons = stringList(f.at("reason"));
  z.message = optionalText(f, "message");
  if (f.has("applicability")) {
    const Node list = f.at("applicability");
    for (std::size_t i = 0; i < list.array().size(); ++i) z.applicability.push_back(applicability(list.item(i), z, true));
  }
  const Node geometry = f.at("geometry");
  const json& volumes = geometry.array();
  if (volumes.empty()) geometry.fail("at least one volume");
  for (std::size_t i = 0; i < volumes.size(); ++i) {
    const Node g = geometry.item(i);
    const double scale = g.has("uomDimensions") ? unitScale(g.at("uomDimensions")) : 1.0;
    Volume v;
    v.lower = limit(g.at("lowerLimit"), reference(g.at("lowerVerticalReference")), scale, false);
    v.upper = limit(g.at("upperLimit"), reference(g.at("upperVerticalReference")), scale, true);
    const Node h = g.at("horizontalProjection");
    const std::string type = h.at("type").str();
    if (type == "Polygon") {
      v.outline = polygonOutline(h.at("coordinates"));
    } else if (type == "Circle") {
      v.outline = circleOutline(position(h.at("center"), false), h.at("radius"), scale);
    } else {
      h.at("type").fail("Polygon or Circle");
    }
    z.volumes.push_back(std::move(v));
  }
  return z;
}

std::vector<Zone> parseEd269(const json& doc, const std::string& source) {
  const Node root{doc, "", source};
  const char* key = doc.contains("UASZoneList") ? "UASZoneList" : "features";
  const Node list{root.at(key).j, key, source};
  std::vector<Zone> zones;
  for (std::size_t i = 0; i < list.array().size(); ++i) zones.push_back(ed269Zone(list.item(i)));
  return zones;
}

// --- GeoJSON (ED-318 and plain) --------------------------------------------

/// Where a GeoJSON flavour keeps its vertical limits.
struct LimitKeys {
  const char* lower;
  const char* upper;
  const char* lower_reference;
  const char* upper_reference;
  VerticalReference default_reference;
  double unlimited_value;  ///< a ceiling at or above this is unlimited
};

/// ED-318 `layer` (references default to AGL; 99999 = unlimited).
constexpr LimitKeys kEd318Layer{"lower", "upper", "lowerReference", "upperReference", VerticalReference::kAgl,
                                kEd318Unlimited};
/// Plain GeoJSON properties (README "Zone files"; references default to AMSL).
constexpr LimitKeys kPlainProperties{"lower", "upper", "lower_reference", "upper_reference", VerticalReference::kAmsl,
                                     std::numeric_limits<double>::infinity()};

/// Floor and ceiling from `n` under `keys`; absent or null values: no floor / unlimited.
std::pair<VerticalLimit, VerticalLimit> geoJsonLimits(const Node& n, const LimitKeys& keys) {
  const double scale = n.has("uom") ? unitScale(n.at("uom")) : 1.0;
  const auto ref = [&](const char* key) { return n.has(key) ? reference(n.at(key)) : keys.default_reference; };
  return {limit(n.orNull(keys.lower), ref(keys.lower_reference), scale, false),
          limit(n.orNull(keys.upper), ref(keys.upper_reference), scale, true, keys.unlimited_value)};
}

void geoJsonVolumes(const Node& geometry, const Node& props, bool ed318,
                    const std::optional<std::pair<VerticalLimit, VerticalLimit>>& inherited, Zone& z) {
  const std::string type = geometry.at("type").str();
  if (type == "GeometryCollection") {
    const Node members = geometry.at("geometries");
    std::optional<std::pair<VerticalLimit, VerticalLimit>> own;
    if (ed318 && geometry.has("layer")) own = geoJsonLimits(geometry.at("layer"), kEd318Layer);
    for (std::size_t i = 0; i < members.array().size(); ++i) {
      geoJsonVolumes(members.item(i), props, ed318, own ? own : inherited, z);
    }
    return;
  }
  std::pair<VerticalLimit, VerticalLimit> limits;
  if (ed318) {
    if (geometry.has("layer")) {
      limits = geoJsonLimits(geometry.at("layer"), kEd318Layer);
    } else if (inherited) {
      limits = *inherited;
    } else {
      const json empty = json::object();
      limits = geoJsonLimits(Node{empty, geometry.path + ".layer", geometry.source}, kEd318Layer);
      z.notes.push_back(geometry.path + " has no layer: surface (no floor) to unlimited");
    }
  } else {
    limits = geoJsonLimits(props, kPlainProperties);
  }
  const auto add = [&](Outline o) { z.volumes.push_back({std::move(o), limits.first, limits.second}); };
  if (type == "Polygon") {
    add(polygonOutline(geometry.at("coordinates")));
  } else if (type == "MultiPolygon") {
    const Node polys = geometry.at("coordinates");
    for (std::size_t i = 0; i < polys.array().size(); ++i) add(polygonOutline(polys.item(i)));
  } else if (type == "Point") {
    const LatLon c = position(geometry.at("coordinates"), false);
    if (geometry.has("extent")) {  // ED-318 / LayeredGeoJSON HorizontalExtent
      const Node e = geometry.at("extent");
      if (e.at("subType").str() != "Circle") e.at("subType").fail("Circle");
      add(circleOutline(c, e.at("radius"), 1.0));
    } else if (!ed318 && props.has("radius_m")) {
      add(circleOutline(c, props.at("radius_m"), 1.0));
    } else if (!ed318 && props.has("subType") && props.at("subType").str() == "Circle") {
      add(circleOutline(c, props.at("radius"), 1.0));
    } else {
      geometry.fail(ed318 ? "a Point with extent {subType: Circle, radius}" : "a Point with a radius_m property");
    }
  } else {
    geometry.at("type").fail("Polygon, MultiPolygon, Point (circle) or GeometryCollection");
  }
}

Zone geoJsonZone(const Node& feature, bool ed318) {
  Zone z;
  z.source = feature.source;
  const json empty = json::object();
  const Node props0 = feature.has("properties") ? feature.at("properties") : Node{empty, feature.path + ".properties", feature.source};
  if (props0.has("identifier")) {
    z.identifier = text(props0.at("identifier"));
  } else if (feature.has("id")) {
    z.identifier = feature.at("id").j.is_string() ? feature.at("id").str() : feature.at("id").j.dump();
  }
  z.feature = featureLabel(feature.path, z);
  const Node f{feature.j, z.feature, feature.source};
  const Node props{props0.j, z.feature + ".properties", feature.source};
  z.name = optionalText(props, "name");
  z.country = optionalText(props, "country");
  const char* restriction_key = ed318 ? "type" : "restriction";
  const bool keep_in_property = !ed318 && props.has("keep_in") && props.at("keep_in").boolean();
  if (props.has(restriction_key)) {
    const Node r = props.at(restriction_key);
    const std::string word = r.str();
    const auto restriction = parseRestriction(word);
    // A keep-in zone: plain GeoJSON only (ED-269 and ED-318 have no such restriction).
    const bool keep_in_word = !ed318 && word == "KEEP_IN";
    z.keep_in = keep_in_property || keep_in_word;
    if (!restriction && !keep_in_word) {
      r.fail(ed318 ? "PROHIBITED, REQ_AUTHORIZATION, CONDITIONAL or NO_RESTRICTION"
                   : "PROHIBITED, REQ_AUTHORISATION, CONDITIONAL, NO_RESTRICTION or KEEP_IN");
    }
    z.restriction = restriction.value_or(Restriction::kProhibited);
  } else if (ed318) {
    throw ParseError(feature.source, 0, props.path + "." + restriction_key, "", "a zone type (ED-318 requires it)");
  } else {
    z.restriction = Restriction::kProhibited;
    z.keep_in = keep_in_property;
    if (!z.keep_in) z.notes.push_back(z.feature + " has no restriction property: taken as PROHIBITED");
  }
  if (props.has("reason")) z.reasons = stringList(props.at("reason"));
  z.message = optionalText(props, "message");
  if (ed318) {
    if (props.has("limitedApplicability")) {
      const Node list = props.at("limitedApplicability");
      for (std::size_t i = 0; i < list.array().size(); ++i) z.applicability.push_back(applicability(list.item(i), z, false));
    }
  } else if (props.has("start") || props.has("end") || props.has("schedule")) {
    Applicability a;
    a.permanent = false;
    a.start = dateTime(props, "start");
    a.end = dateTime(props, "end");
    if (a.start && a.end && !(*a.end - *a.start > 0.0)) props.at("end").fail("a date-time after start");
    a.schedule = schedule(props, z);
    z.applicability.push_back(std::move(a));
  }
  geoJsonVolumes(f.at("geometry"), props, ed318, std::nullopt, z);
  return z;
}

std::vector<Zone> parseGeoJson(const json& doc, const std::string& source, bool ed318) {
  const Node root{doc, "", source};
  std::vector<Zone> zones;
  if (doc.is_object() && stringMember(doc, "type") == "Feature") {
    zones.push_back(geoJsonZone(Node{doc, "feature", source}, ed318));
    return zones;
  }
  const Node list{root.at("features").j, "features", source};
  for (std::size_t i = 0; i < list.array().size(); ++i) zones.push_back(geoJsonZone(list.item(i), ed318));
  return zones;
}

// --- QGroundControl .plan ----------------------------------------------------

std::vector<Zone> parseQgcPlan(const json& doc, const std::string& source) {
  const Node root{doc, "", source};
  const Node fence{root.at("geoFence").j, "geoFence", source};
  std::vector<Zone> zones;
  const auto make = [&](const Node& item, const std::string& kind, std::size_t i) {
    Zone z;
    z.source = source;
    z.identifier = kind + "-" + std::to_string(i + 1);
    z.feature = item.path;
    const bool inclusion = item.has("inclusion") ? item.at("inclusion").boolean() : false;
    z.keep_in = inclusion;
    z.restriction = Restriction::kProhibited;
    z.name = std::string(inclusion ? "inclusion " : "exclusion ") + kind;
    z.message = inclusion ? "QGroundControl inclusion fence: stay inside" : "QGroundControl exclusion fence: keep out";
    return z;
  };
  const auto everyHeight = [](Outline o) {
    Volume v;
    v.outline = std::move(o);
    v.lower.unlimited = true;
    v.lower.as_given = "no floor";
    v.upper.unlimited = true;
    v.upper.as_given = "unlimited";
    return v;
  };
  if (fence.has("polygons")) {
    const Node list = fence.at("polygons");
    for (std::size_t i = 0; i < list.array().size(); ++i) {
      const Node item = list.item(i);
      Zone z = make(item, "polygon", i);
      Outline o;
      o.ring = ring(item.at("polygon"), /*lat_first=*/true);
      z.volumes.push_back(everyHeight(std::move(o)));
      zones.push_back(std::move(z));
    }
  }
  if (fence.has("circles")) {
    const Node list = fence.at("circles");
    for (std::size_t i = 0; i < list.array().size(); ++i) {
      const Node item = list.item(i);
      Zone z = make(item, "circle", i);
      const Node c = item.at("circle");
      z.volumes.push_back(everyHeight(circleOutline(position(c.at("center"), true), c.at("radius"), 1.0)));
      zones.push_back(std::move(z));
    }
  }
  return zones;
}

}  // namespace

std::string_view formatName(ZoneFormat f) {
  switch (f) {
    case ZoneFormat::kAuto: return "auto";
    case ZoneFormat::kEd269: return "ed269";
    case ZoneFormat::kEd318: return "ed318";
    case ZoneFormat::kGeoJson: return "geojson";
    case ZoneFormat::kQgcPlan: return "qgc";
  }
  return "?";
}

std::optional<ZoneFormat> parseZoneFormat(std::string_view text) {
  for (ZoneFormat f : {ZoneFormat::kAuto, ZoneFormat::kEd269, ZoneFormat::kEd318, ZoneFormat::kGeoJson,
                       ZoneFormat::kQgcPlan}) {
    if (formatName(f) == text) return f;
  }
  return std::nullopt;
}

std::optional<ZoneFormat> detectZoneFormat(const json& doc) {
  if (!doc.is_object()) return std::nullopt;
  if (doc.contains("UASZoneList")) return ZoneFormat::kEd269;
  if (stringMember(doc, "fileType") == "Plan" || doc.contains("geoFence")) return ZoneFormat::kQgcPlan;
  if (stringMember(doc, "type") == "Feature") return ZoneFormat::kGeoJson;
  const auto features = doc.find("features");
  if (features == doc.end() || !features->is_array()) return std::nullopt;
  for (const json& f : *features) {
    if (!f.is_object()) continue;
    if (f.contains("geometry") && f["geometry"].is_array()) return ZoneFormat::kEd269;
    const auto props = f.find("properties");
    const auto geometry = f.find("geometry");
    if ((props != f.end() && props->is_object() && (props->contains("variant") || props->contains("zoneAuthority"))) ||
        (geometry != f.end() && geometry->is_object() && geometry->contains("layer"))) {
      return ZoneFormat::kEd318;
    }
  }
  return ZoneFormat::kGeoJson;
}

std::vector<Zone> parseZones(const json& doc, const std::string& source, ZoneFormat format) {
  if (format == ZoneFormat::kAuto) {
    const auto detected = detectZoneFormat(doc);
    if (!detected) {
      throw ParseError(source, 0, "(format)", quoteJson(doc),
                       "an ED-269 zone list, an ED-318 or GeoJSON FeatureCollection, or a QGroundControl .plan");
    }
    format = *detected;
  }
  switch (format) {
    case ZoneFormat::kEd269: return parseEd269(doc, source);
    case ZoneFormat::kEd318: return parseGeoJson(doc, source, true);
    case ZoneFormat::kGeoJson: return parseGeoJson(doc, source, false);
    case ZoneFormat::kQgcPlan: return parseQgcPlan(doc, source);
    case ZoneFormat::kAuto: break;
  }
  throw std::logic_error("parseZones: unhandled format");
}

std::vector<Zone> readZoneFile(const std::string& path, ZoneFormat format) {
  return parseZones(maps::readJsonFile(path), path, format);
}

}  // namespace skylane::airspace
