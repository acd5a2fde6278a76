/// \file
/// \brief Zone sets: upload and new versions (ED-269, ED-318, GeoJSON, QGroundControl fences),
/// the list, a version as GeoJSON, and the zones at a point and time or in a box and window.

#include "airspace/applicability.hpp"
#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "airspace/zone_export.hpp"
#include "airspace/zone_geometry.hpp"
#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "maps/parse_error.hpp"
#include "maps/terrain.hpp"
#include "maps/text_file.hpp"
#include "maps/time.hpp"
#include "service/service_impl.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <variant>

namespace skylane::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// The zone sets' limits resolved over flat ground at 0 m AMSL (a service without terrain).
const airspace::VerticalModel& flatModel() {
  static const maps::Terrain terrain = maps::Terrain::flat(0.0);
  static const airspace::VerticalModel model{terrain, maps::Geoid::egm96()};
  return model;
}

json zoneSetJson(const ZoneSet& z) {
  return {{"id", z.id},
          {"name", z.name},
          {"owner", z.owner.empty() ? std::string("authority") : z.owner},
          {"public", z.owner.empty()},
          {"version", z.latest().version},
          {"zones", z.latest().zones},
          {"created", z.created},
          {"updated", z.latest().created}};
}

/// The uploaded document's zones, validated, or the 400 that says why not.
std::variant<std::vector<airspace::Zone>, HttpResponse> parseUpload(const std::string& body) {
  try {
    const json doc = maps::parseJsonText(body, "the request body");
    std::vector<airspace::Zone> zones = airspace::parseZones(doc, "the request body");
    const airspace::ValidationReport report = airspace::validateZones(zones, false);
    if (const airspace::ZoneIssue* e = report.firstError()) {
      return errorResponse(400, "the request body: " + zones[e->zone].feature + ": " + e->what + "; expected a valid zone");
    }
    if (zones.empty()) return errorResponse(400, "the request body: no zones; expected at least one");
    return zones;
  } catch (const std::exception& e) {
    return errorResponse(400, e.what());
  }
}

/// The time of a query parameter, or a 400.
std::variant<maps::GpsTime, HttpResponse> queryTime(const HttpRequest& r, const char* name) {
  const std::optional<maps::GpsTime> t = maps::parseRfc3339(r.param(name));
  if (t) return *t;
  return errorResponse(400, std::string("query parameter ") + name + "=\"" + r.param(name).substr(0, 64) +
                                "\": expected an RFC 3339 time such as 2026-12-02T12:00:00Z");
}

std::optional<double> queryNumber(const HttpRequest& r, const char* name) {
  const std::string v = r.param(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d)) return std::nullopt;
  return d;
}

/// Whether an outline's bounding box meets [w, e] × [s, n] (radians).
bool outlineMeetsBox(const airspace::Outline& o, double w, double s, double e, double n) {
  double lo_lat = 1e9, hi_lat = -1e9, lo_lon = 1e9, hi_lon = -1e9;
  if (o.kind == airspace::Outline::Kind::kCircle) {
    const double dlat = o.radius_m / 6.3e6, dlon = dlat / std::max(1e-6, std::cos(o.centre.lat_rad));
    lo_lat = o.centre.lat_rad - dlat, hi_lat = o.centre.lat_rad + dlat;
    lo_lon = o.centre.lon_rad - dlon, hi_lon = o.centre.lon_rad + dlon;
  }
  for (const airspace::LatLon& p : o.ring) {
    lo_lat = std::min(lo_lat, p.lat_rad), hi_lat = std::max(hi_lat, p.lat_rad);
    lo_lon = std::min(lo_lon, p.lon_rad), hi_lon = std::max(hi_lon, p.lon_rad);
  }
  return hi_lat >= s && lo_lat <= n && hi_lon >= w && lo_lon <= e;
}

}  // namespace

LoadedZoneSet* ServiceImpl::visibleZoneSet(const Principal& who, const std::string& id) {
  const auto it = zonesets.find(id);
  if (it == zonesets.end()) return nullptr;
  const std::string& owner = it->second.set.owner;
  return owner.empty() || owner == who.owner() ? &it->second : nullptr;
}

const std::vector<airspace::Zone>& ServiceImpl::zonesOf(LoadedZoneSet& z, int version) {
  auto it = z.zones.find(version);
  if (it != z.zones.end()) return it->second;
  for (const ZoneSetVersion& v : z.set.versions) {
    if (v.version == version) return z.zones[version] = airspace::loadZones((files / v.file).string());
  }
  throw std::out_of_range("zone set " + z.set.id + " has no version " + std::to_string(version));
}

HttpResponse ServiceImpl::zoneSets(const HttpRequest& r, const Principal& who, const Segments& s) {
  if (s.size() == 2) {
    if (r.method == "POST") return uploadZoneSet(r, who, {});
    if (r.method != "GET") return methodNotAllowed("GET, POST");
    json list = json::array();
    for (const auto& [id, z] : zonesets) {
      if (z.set.owner.empty() || z.set.owner == who.owner()) list.push_back(zoneSetJson(z.set));
    }
    return jsonBody(200, {{"zonesets", list}});
  }
  LoadedZoneSet* z = visibleZoneSet(who, s[2]);
  if (!z) return notFound("zone set " + s[2]);
  if (s.size() == 3) {
    if (r.method == "PUT") return uploadZoneSet(r, who, s[2]);
    if (r.method != "GET") return methodNotAllowed("GET, PUT");
    json versions = json::array();
    for (const ZoneSetVersion& v : z->set.versions) versions.push_back({{"version", v.version}, {"zones", v.zones}, {"created", v.created}});
    json j = zoneSetJson(z->set);
    j["versions"] = versions;
    return jsonBody(200, j);
  }
  if (s.size() == 4 && s[3] == "geojson") {
    if (r.method != "GET") return methodNotAllowed("GET");
    return zoneSetGeoJson(r, who, s[2]);
  }
  return notFound("route " + r.path);
}

HttpResponse ServiceImpl::uploadZoneSet(const HttpRequest& r, const Principal& who, const std::string& id) {
  if (auto bad = requireContentType(r, {"application/json", "application/geo+json"})) return *bad;
  LoadedZoneSet* existing = id.empty() ? nullptr : visibleZoneSet(who, id);
  if (existing && existing->set.owner != who.owner()) return errorResponse(403, "zone set " + id + " belongs to the authority");
  const std::string name = id.empty() ? r.param("name") : existing->set.name;
  if (name.empty() || name.size() > 200) return errorResponse(400, "query parameter name: expected a zone set name of 1 to 200 characters");
  auto parsed = parseUpload(r.body);
  if (auto* bad = std::get_if<HttpResponse>(&parsed)) return *bad;
  auto& zones = std::get<std::vector<airspace::Zone>>(parsed);
  // An operator's own set is for its own missions: it may keep its vehicles in or out, never
  // lift or change what the authority published.
  const std::string set_id = id.empty() ? newId("zs-") : id;
  const int version = existing ? existing->set.latest().version + 1 : 1;
  const std::string rel = "zonesets/" + set_id + "/v" + std::to_string(version) + ".json";
  fs::create_directories(files / "zonesets" / set_id);
  writeFileAtomically(files / rel, r.body);
  const ZoneSetVersion v{version, rel, static_cast<int>(zones.size()), nowUtc()};
  if (existing) {
    store->addZoneSetVersion(set_id, v);
    existing->set.versions.push_back(v);
  } else {
    ZoneSet z{set_id, who.owner(), name, v.created, {v}};
    store->addZoneSet(z);
    zonesets[set_id] = {z, {}};
  }
  zonesets[set_id].zones[version] = airspace::loadZones((files / rel).string());
  if (nats) {
    try {
      natsPutZoneSet(zonesets[set_id].set);
    } catch (const NatsError& e) {  // kept here; put into NATS at the next start
      log("zone set " + set_id + " version " + std::to_string(version) + " not yet in NATS: " + e.what());
    }
  }
  log("zone set " + set_id + " version " + std::to_string(version) + " (" + std::to_string(zones.size()) + " zones) by " +
      (who.authority ? "the authority" : who.owner()));
  return jsonBody(existing ? 200 : 201, zoneSetJson(zonesets[set_id].set));
}

HttpResponse ServiceImpl::zoneSetGeoJson(const HttpRequest& r, const Principal& who, const std::string& id) {
  LoadedZoneSet& z = *visibleZoneSet(who, id);
  int version = z.set.latest().version;
  if (!r.param("version").empty()) {
    const auto v = queryNumber(r, "version");
    if (!v || *v != std::floor(*v) || *v < 1 || *v > version) {
      return errorResponse(400, "query parameter version=\"" + r.param("version").substr(0, 32) + "\": expected 1 to " + std::to_string(version));
    }
    version = static_cast<int>(*v);
  }
  json features = json::array();
  for (const airspace::Zone& zone : zonesOf(z, version)) {
    for (json& f : airspace::zoneFeatures(zone, flatModel())) {
      f["properties"]["zoneset"] = id;
      f["properties"]["zoneset_version"] = version;
      features.push_back(std::move(f));
    }
  }
  HttpResponse res = jsonBody(200, {{"type", "FeatureCollection"}, {"name", z.set.name}, {"features", features}});
  res.content_type = "application/geo+json";
  return res;
}

HttpResponse ServiceImpl::zonesQuery(const HttpRequest& r, const Principal& who) {
  const bool by_point = !r.param("lat").empty() || !r.param("lon").empty();
  const bool by_box = !r.param("bbox").empty();
  if (by_point == by_box) return errorResponse(400, "query: expected either lat, lon, time (and alt_m) or bbox=W,S,E,N (and from, to)");
  std::function<bool(const airspace::Zone&)> wanted;
  if (by_point) {
    const auto lat = queryNumber(r, "lat"), lon = queryNumber(r, "lon");
    if (!lat || std::abs(*lat) > 90) return errorResponse(400, "query parameter lat: expected a latitude in degrees, -90 to 90");
    if (!lon || std::abs(*lon) > 180) return errorResponse(400, "query parameter lon: expected a longitude in degrees, -180 to 180");
    auto t = queryTime(r, "time");
    if (auto* bad = std::get_if<HttpResponse>(&t)) return *bad;
    const std::optional<double> alt = r.param("alt_m").empty() ? std::nullopt : queryNumber(r, "alt_m");
    if (!r.param("alt_m").empty() && (!alt || std::abs(*alt) > 1e5)) {
      return errorResponse(400, "query parameter alt_m: expected a height above the WGS-84 ellipsoid in metres within ±100 km");
    }
    const airspace::LatLon p{maps::deg2rad(*lat), maps::deg2rad(*lon)};
    const maps::GpsTime at = std::get<maps::GpsTime>(t);
    wanted = [p, at, alt](const airspace::Zone& z) {
      if (!airspace::isActive(z, at)) return false;
      for (const airspace::Volume& v : z.volumes) {
        if (airspace::horizontalSide(v.outline, p) == airspace::Side::kOutside) continue;
        if (!alt) return true;
        const auto lo = airspace::limitHeightEllipsoid_m(v.lower, false, p, flatModel());
        const auto hi = airspace::limitHeightEllipsoid_m(v.upper, true, p, flatModel());
        if ((!lo || *lo <= *alt) && (!hi || *alt <= *hi)) return true;
      }
      return false;
    };
  } else {
    double b[4];
    std::istringstream in(r.param("bbox"));
    char c1 = 0, c2 = 0, c3 = 0;
    in >> b[0] >> c1 >> b[1] >> c2 >> b[2] >> c3 >> b[3];
    if (!in || c1 != ',' || c2 != ',' || c3 != ',' || !(in >> std::ws).eof() || b[0] > b[2] || b[1] > b[3]) {
      return errorResponse(400, "query parameter bbox=\"" + r.param("bbox").substr(0, 64) + "\": expected W,S,E,N in degrees with W ≤ E and S ≤ N");
    }
    std::optional<std::pair<maps::GpsTime, maps::GpsTime>> window;
    if (!r.param("from").empty() || !r.param("to").empty()) {
      auto from = queryTime(r, "from"), to = queryTime(r, "to");
      if (auto* bad = std::get_if<HttpResponse>(&from)) return *bad;
      if (auto* bad = std::get_if<HttpResponse>(&to)) return *bad;
      window = std::make_pair(std::get<maps::GpsTime>(from), std::get<maps::GpsTime>(to));
    }
    const double w = maps::deg2rad(b[0]), s = maps::deg2rad(b[1]), e = maps::deg2rad(b[2]), n = maps::deg2rad(b[3]);
    wanted = [=](const airspace::Zone& z) {
      if (window && !airspace::isActiveDuring(z, window->first, window->second)) return false;
      for (const airspace::Volume& v : z.volumes) {
        if (outlineMeetsBox(v.outline, w, s, e, n)) return true;
      }
      return false;
    };
  }
  json features = json::array();
  for (auto& [id, z] : zonesets) {
    if (!z.set.owner.empty() && z.set.owner != who.owner()) continue;
    for (const airspace::Zone& zone : zonesOf(z, z.set.latest().version)) {
      if (!wanted(zone)) continue;
      for (json& f : airspace::zoneFeatures(zone, flatModel())) {
        f["properties"]["zoneset"] = id;
        features.push_back(std::move(f));
      }
    }
  }
  HttpResponse res = jsonBody(200, {{"type", "FeatureCollection"}, {"features", features}});
  res.content_type = "application/geo+json";
  return res;
}

}  // namespace skylane::service
