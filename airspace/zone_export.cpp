#include "airspace/zone_export.hpp"

#include "airspace/applicability.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_numbers.hpp"
#include "maps/time.hpp"

#include <cmath>

namespace skylane::airspace {

namespace {

using nlohmann::json;

/// A limit's resolved range over the outline (limitRange), both references.
json resolvedRange(const VerticalLimit& l, bool ceiling, const Outline& o, const VerticalModel& model) {
  const auto r = limitRange(l, ceiling, o, model);
  if (!r) return json("unknown terrain");
  return {{"h_ell_m", {maps::metresOrNull(r->h_ell_min_m), maps::metresOrNull(r->h_ell_max_m)}},
          {"alt_amsl_m", {maps::metresOrNull(r->alt_amsl_min_m), maps::metresOrNull(r->alt_amsl_max_m)}}};
}

json positionJson(const LatLon& p) {
  return json::array({std::round(maps::rad2deg(p.lon_rad) * 1e9) / 1e9, std::round(maps::rad2deg(p.lat_rad) * 1e9) / 1e9});
}

json outlineGeometry(const Outline& o) {
  if (o.kind == Outline::Kind::kPolygon) {
    json ring = json::array();
    for (const LatLon& p : o.ring) ring.push_back(positionJson(p));
    ring.push_back(positionJson(o.ring.front()));
    return {{"type", "Polygon"}, {"coordinates", json::array({ring})}};
  }
  return {{"type", "Point"}, {"coordinates", positionJson(o.centre)}};
}

}  // namespace

json limitJson(const VerticalLimit& l) {
  json j;
  j["as_given"] = l.as_given;
  j["reference"] = std::string(referenceName(l.reference));
  j["value_m"] = l.unlimited ? json(nullptr) : json(maps::roundToMm(l.value_m));
  j["unlimited"] = l.unlimited;
  return j;
}

json applicabilityJson(const Zone& z) {
  json list = json::array();
  for (const Applicability& a : z.applicability) {
    json j;
    j["permanent"] = a.permanent;
    if (a.start) j["start"] = maps::formatRfc3339(*a.start);
    if (a.end) j["end"] = maps::formatRfc3339(*a.end);
    json schedule = json::array();
    for (const DailyPeriod& p : a.schedule) {
      json days = json::array();
      for (unsigned d = 0; d < 7; ++d) {
        if (p.days & (1u << d)) days.push_back(weekdayName(d));
      }
      schedule.push_back({{"day", days}, {"start_utc_s", p.start_s}, {"end_utc_s", p.end_s}});
    }
    if (!schedule.empty()) j["schedule"] = schedule;
    list.push_back(j);
  }
  return list;
}

std::vector<json> zoneFeatures(const Zone& z, const VerticalModel& model) {
  std::vector<json> out;
  for (std::size_t vi = 0; vi < z.volumes.size(); ++vi) {
    const Volume& v = z.volumes[vi];
    json props;
    if (v.outline.kind == Outline::Kind::kCircle) props["radius_m"] = v.outline.radius_m;
    props["identifier"] = z.identifier;
    props["name"] = z.name;
    props["restriction"] = std::string(restrictionLabel(z));
    props["keep_in"] = z.keep_in;
    props["reason"] = z.reasons;
    props["message"] = z.message;
    props["volume"] = vi;
    props["source"] = z.source;
    props["feature"] = z.feature;
    props["lower"] = limitJson(v.lower);
    props["upper"] = limitJson(v.upper);
    props["lower_resolved"] = resolvedRange(v.lower, false, v.outline, model);
    props["upper_resolved"] = resolvedRange(v.upper, true, v.outline, model);
    props["applicability"] = applicabilityJson(z);
    if (!z.notes.empty()) props["notes"] = z.notes;
    out.push_back({{"type", "Feature"}, {"geometry", outlineGeometry(v.outline)}, {"properties", props}});
  }
  return out;
}

}  // namespace skylane::airspace
