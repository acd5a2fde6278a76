/// \file
/// \brief libFuzzer target for the zone loaders (airspace/loaders.hpp: ED-269, ED-318, plain
/// GeoJSON, QGroundControl .plan — the format is detected from the document, so one target
/// reaches all four) and the validator. Syntax errors are nlohmann's business and skipped.
/// A parsed zone list is validated with and without repair; then every polygon left valid
/// must have ≥ 3 vertices, finite coordinates and a counter-clockwise ring, and the
/// point-in-zone predicate and the applicability rules must answer without throwing. The
/// geometry services run on every valid volume: convex pieces must be convex and add up to the
/// ring's area; an outward buffer must hold the ring's vertices; a circle's circumscribed
/// polygon must hold its centre. A ring valid in longitude/latitude may stop being simple once
/// projected (a continent-sized or polar ring): the services refuse it with invalid_argument.

#include "airspace/applicability.hpp"
#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "airspace/zone_geometry.hpp"
#include "fuzz/fuzz_common.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void exerciseGeometry(const airspace::Zone& z, const airspace::Outline& o) {
  const maps::PlaneFrame frame(o.ring[0].lat_rad, o.ring[0].lon_rad);
  const airspace::PlanarRing ring = airspace::projectOutline(o, frame, 1.0, airspace::SafeSide::kContain);
  try {
    double area_sum = 0.0;
    for (const airspace::PlanarRing& piece : airspace::convexPieces(ring)) {
      area_sum += airspace::twiceSignedArea_m2(piece);
      for (std::size_t k = 0; k < piece.size(); ++k) {
        const Eigen::Vector2d e1 = piece[(k + 1) % piece.size()] - piece[k];
        const Eigen::Vector2d e2 = piece[(k + 2) % piece.size()] - piece[(k + 1) % piece.size()];
        SKYLANE_FUZZ_CHECK(e1.x() * e2.y() - e1.y() * e2.x() >= -1e-9 * e1.norm() * e2.norm(), describe(z));
      }
    }
    const double area = airspace::twiceSignedArea_m2(ring);
    SKYLANE_FUZZ_CHECK(std::abs(area_sum - area) <= 1e-6 * area, describe(z));
  } catch (const std::invalid_argument&) {
    // not simple once projected: refused, as documented
  }
  try {
    const airspace::Outline buffered = airspace::bufferOutline(o, 10.0, 1.0);
    for (const airspace::LatLon& p : o.ring) {
      SKYLANE_FUZZ_CHECK(airspace::horizontalSide(buffered, p) == airspace::Side::kInside, describe(z));
    }
  } catch (const std::invalid_argument&) {
  }
}

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
        if (v.outline.radius_m < 1e6) {
          const airspace::Outline poly =
              airspace::circleToPolygon(v.outline, std::max(0.01, v.outline.radius_m / 100), airspace::SafeSide::kContain);
          SKYLANE_FUZZ_CHECK(airspace::horizontalSide(poly, v.outline.centre) == airspace::Side::kInside, describe(zones[i]));
        }
        continue;
      }
      SKYLANE_FUZZ_CHECK(v.outline.ring.size() >= 3, describe(zones[i]));
      for (const airspace::LatLon& p : v.outline.ring) {
        SKYLANE_FUZZ_CHECK(std::isfinite(p.lat_rad) && std::isfinite(p.lon_rad), describe(zones[i]));
      }
      // The ring's first vertex lies on its own boundary.
      SKYLANE_FUZZ_CHECK(airspace::horizontalSide(v.outline, v.outline.ring[0]) != airspace::Side::kInside,
                         describe(zones[i]));
      exerciseGeometry(zones[i], v.outline);
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
