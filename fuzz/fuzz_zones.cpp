/// \file
/// \brief libFuzzer target for the zone loaders (airspace/loaders.hpp: ED-269, ED-318, plain
/// GeoJSON, QGroundControl .plan — the format is detected from the document, so one target
/// reaches all four) and the validator. Syntax errors are nlohmann's business and skipped.
/// A parsed zone list is validated with and without repair; then every polygon left valid
/// must have ≥ 3 vertices, finite coordinates and a counter-clockwise ring, and the
/// point-in-zone predicate and the applicability rules must answer without throwing.

#include "airspace/applicability.hpp"
#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "airspace/zone_geometry.hpp"
#include "fuzz/fuzz_common.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void exerciseZones(std::vector<airspace::Zone> zones, bool repair) {
  const airspace::ValidationReport report = airspace::validateZones(zones, repair);
  const maps::GpsTime t = *maps::parseRfc3339("2026-06-13T21:30:00Z");
  for (std::size_t i = 0; i < zones.size(); ++i) {
    bool zone_ok = true;
    for (const airspace::ZoneIssue& issue : report.issues) {
      if (issue.zone == i && issue.error && !issue.repaired) zone_ok = false;
      SKYLANE_FUZZ_CHECK(!issue.message.empty(), "issue without a message");
    }
    (void)airspace::isActive(zones[i], t);
    (void)airspace::isActiveDuring(zones[i], t, t.plus(86400.0 * 30));
    if (!zone_ok) continue;
    for (const airspace::Volume& v : zones[i].volumes) {
      if (v.outline.kind == airspace::Outline::Kind::kCircle) {
        SKYLANE_FUZZ_CHECK(v.outline.radius_m > 0.0, std::to_string(v.outline.radius_m));
        (void)airspace::horizontalSide(v.outline, v.outline.centre);
        continue;
      }
      SKYLANE_FUZZ_CHECK(v.outline.ring.size() >= 3, describe(zones[i]));
      for (const airspace::LatLon& p : v.outline.ring) {
        SKYLANE_FUZZ_CHECK(std::isfinite(p.lat_rad) && std::isfinite(p.lon_rad), describe(zones[i]));
      }
      // The ring's first vertex lies on its own boundary.
      SKYLANE_FUZZ_CHECK(airspace::horizontalSide(v.outline, v.outline.ring[0]) != airspace::Side::kInside,
                         describe(zones[i]));
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string kSource = "fuzz.json";
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return 0;
  fuzz::parseThenUse(kSource, [&] { return airspace::parseZones(doc, kSource); },
                     [](const std::vector<airspace::Zone>& zones) {
                       exerciseZones(zones, false);
                       exerciseZones(zones, true);
                     });
  return 0;
}
