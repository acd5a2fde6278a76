// Keep-in zones (issue 17): the protection volume must lie inside the union of the active keep-in
// zones. The margins are checked against closed forms (a rectangle's distances), and, over random
// rings and volumes, against an independent oracle that samples the disk and tests each point
// with the exact bounded-side predicate.
#include "geofence/keep_in.hpp"

#include "airspace/validation.hpp"
#include "geofence/fence.hpp"
#include "geofence/obstruction_files.hpp"
#include "geofence/verdict_json.hpp"
#include "maps/geodesy.hpp"
#include "maps/terrain.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>

namespace skylane::geofence {
namespace {

using nlohmann::json;
constexpr double kInf = std::numeric_limits<double>::infinity();

KeepInVolume box(double x0, double y0, double x1, double y1, double floor = -kInf, double ceiling = kInf,
                 std::size_t zone = 0) {
  KeepInVolume k;
  k.ring = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  k.floor_h_ell_m = floor;
  k.ceiling_h_ell_m = ceiling;
  k.zone = zone;
  return k;
}

ProtectionVolume at(double x, double y, double z, double hpl, double vpl) {
  return {Eigen::Vector3d(x, y, z), hpl, vpl};
}

TEST(KeepIn, SignedDistanceToARing) {
  const airspace::PlanarRing square = box(0, 0, 100, 100).ring;
  EXPECT_DOUBLE_EQ(signedDistanceToRing({50, 50}, square), 50.0);
  EXPECT_DOUBLE_EQ(signedDistanceToRing({10, 70}, square), 10.0);
  EXPECT_DOUBLE_EQ(signedDistanceToRing({150, 50}, square), -50.0);
  EXPECT_DOUBLE_EQ(signedDistanceToRing({103, 104}, square), -5.0);  // to the corner
  EXPECT_DOUBLE_EQ(signedDistanceToRing({100, 30}, square), 0.0);
}

TEST(KeepIn, OneZoneGivesTheBoxMargins) {
  const KeepInVolume k = box(0, 0, 100, 100, 400.0, 600.0);
  const KeepInMargins m = keepInMargins(at(30, 60, 500, 10, 20), {&k});
  EXPECT_DOUBLE_EQ(m.margin_h_m, 30.0 - 10.0);
  EXPECT_DOUBLE_EQ(m.margin_v_m, 100.0 - 20.0);
  // Too tall: no band holds it; the shortfall is the nearest band's.
  const KeepInMargins tall = keepInMargins(at(30, 60, 500, 10, 120), {&k});
  EXPECT_DOUBLE_EQ(tall.margin_v_m, -20.0);
  EXPECT_THROW((void)keepInMargins(at(0, 0, 0, 1, 1), {}), std::invalid_argument);
}

// Two squares sharing a strip: the union is the rectangle [0, 180] × [0, 100]. A volume over the
// overlap is held by neither square alone but by their union.
TEST(KeepIn, TheUnionHoldsWhatNoSingleZoneDoes) {
  const KeepInVolume a = box(0, 0, 100, 100, -kInf, kInf, 0);
  const KeepInVolume b = box(80, 0, 180, 100, -kInf, kInf, 1);
  const ProtectionVolume v = at(95, 50, 0, 30, 5);
  EXPECT_LT(keepInMargins(v, {&a}).margin_h_m, 0.0);
  EXPECT_LT(keepInMargins(v, {&b}).margin_h_m, 0.0);
  const KeepInMargins both = keepInMargins(v, {&a, &b});
  EXPECT_NEAR(both.margin_h_m, 50.0 - 30.0, 1e-9);  // the rectangle's nearest edge, y = 0 or 100
  // Outside the union: the negative distance to it.
  EXPECT_NEAR(keepInMargins(at(200, 50, 0, 1, 1), {&a, &b}).margin_h_m, -20.0 - 1.0, 1e-9);
}

// A zone whose band does not hold the volume's height interval does not hold it horizontally
// either: beside the low zone, over the tall one's edge, the volume is outside.
TEST(KeepIn, OnlyZonesWhoseBandHoldsTheVolumeCount) {
  const KeepInVolume tall = box(0, 0, 100, 100, 0.0, 200.0, 0);
  const KeepInVolume low = box(100, 0, 200, 100, 0.0, 50.0, 1);
  const ProtectionVolume v = at(105, 50, 100, 10, 10);
  const KeepInMargins m = keepInMargins(v, {&tall, &low});
  EXPECT_NEAR(m.margin_h_m, -5.0 - 10.0, 1e-9);
  EXPECT_EQ(m.nearest, 0u);
  // Low enough for both bands, the union [0, 200] × [0, 100] holds it.
  const KeepInMargins low_v = keepInMargins(at(105, 50, 30, 10, 10), {&tall, &low});
  EXPECT_NEAR(low_v.margin_h_m, 50.0 - 10.0, 1e-9);
  EXPECT_NEAR(low_v.margin_v_m, 10.0, 1e-9);  // 50 − (30 + 10)
}

/// A random star-shaped ring round `c` (simple, counter-clockwise).
airspace::PlanarRing starRing(std::mt19937_64& rng, const Eigen::Vector2d& c, double r_min, double r_max, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  airspace::PlanarRing ring;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * M_PI * (i + 0.3 * u(rng)) / n;
    const double r = r_min + (r_max - r_min) * u(rng);
    ring.push_back(c + r * Eigen::Vector2d(std::cos(t), std::sin(t)));
  }
  return ring;
}

/// The oracle: points of the disk on a polar grid, each tested with the exact predicate against
/// every ring; the least margin found (a lower bound on containment is not claimed: only the sign).
bool diskInsideUnionBySampling(const Eigen::Vector2d& p, double r, const std::vector<airspace::PlanarRing>& rings) {
  for (int ri = 0; ri <= 40; ++ri) {
    const double rho = r * ri / 40.0;
    const int n = ri == 0 ? 1 : 16 * ri;
    for (int k = 0; k < n; ++k) {
      const double t = 2.0 * M_PI * k / n;
      const Eigen::Vector2d q = p + rho * Eigen::Vector2d(std::cos(t), std::sin(t));
      bool in = false;
      for (const airspace::PlanarRing& ring : rings) in = in || airspace::cylinderMeetsPrism({q.x(), q.y(), 0}, 0.0, 0.0, {ring, {}, 0, -1, 1});
      if (!in) return false;
    }
  }
  return true;
}

TEST(KeepIn, MarginSignAgreesWithASampledDiskOverRandomUnions) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int inside = 0, outside = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<KeepInVolume> vols;
    std::vector<airspace::PlanarRing> rings;
    const int count = 1 + trial % 3;
    for (int k = 0; k < count; ++k) {
      KeepInVolume v;
      v.ring = starRing(rng, {120.0 * k + 40 * u(rng), 60 * u(rng)}, 60, 140, 7 + k);
      v.floor_h_ell_m = -kInf;
      v.ceiling_h_ell_m = kInf;
      rings.push_back(v.ring);
      vols.push_back(std::move(v));
    }
    std::vector<const KeepInVolume*> active;
    for (const KeepInVolume& v : vols) active.push_back(&v);
    const Eigen::Vector2d p(-100 + 400 * u(rng), -150 + 300 * u(rng));
    const double hpl = 5 + 40 * u(rng);
    const KeepInMargins m = keepInMargins(at(p.x(), p.y(), 0, hpl, 1), active);
    // The grid's spacing is ≤ 2π·HPL/640 along the rim and HPL/40 radially; beyond that slack the signs must agree.
    const double slack = hpl / 40.0 + 0.02;
    if (std::abs(m.margin_h_m) < slack) continue;
    const bool sampled_inside = diskInsideUnionBySampling(p, hpl, rings);
    EXPECT_EQ(m.margin_h_m > 0, sampled_inside) << "trial " << trial << " margin " << m.margin_h_m;
    (m.margin_h_m > 0 ? inside : outside)++;
  }
  EXPECT_GT(inside, 30);
  EXPECT_GT(outside, 30);
}

// From a GeoJSON file to the fence: a KEEP_IN polygon is loaded as a keep-in zone, checked as
// the keep_in level (inside / outside), and a prohibited zone's check reads clear / met with
// its name and restriction.
TEST(KeepIn, FenceChecksAKeepInZoneAndZoneChecksReadClearOrMet) {
  const double lat0 = 47.0, lon0 = 8.0;
  const double dlat = 200.0 / 111'200.0, dlon = 200.0 / (111'200.0 * std::cos(maps::deg2rad(lat0)));
  json square = json::array({json::array({{lon0 - dlon, lat0 - dlat}, {lon0 + dlon, lat0 - dlat}, {lon0 + dlon, lat0 + dlat},
                                          {lon0 - dlon, lat0 + dlat}, {lon0 - dlon, lat0 - dlat}})});
  json small = json::array({json::array({{lon0 + dlon / 4, lat0 - dlat / 4}, {lon0 + dlon / 2, lat0 - dlat / 4},
                                         {lon0 + dlon / 2, lat0 + dlat / 4}, {lon0 + dlon / 4, lat0 + dlat / 4},
                                         {lon0 + dlon / 4, lat0 - dlat / 4}})});
  json fc{{"type", "FeatureCollection"},
          {"features",
           {{{"type", "Feature"},
             {"properties", {{"identifier", "FENCE"}, {"name", "site"}, {"restriction", "KEEP_IN"}}},
             {"geometry", {{"type", "Polygon"}, {"coordinates", square}}}},
            {{"type", "Feature"},
             {"properties", {{"identifier", "NFZ"}, {"name", "crane"}, {"restriction", "PROHIBITED"}}},
             {"geometry", {{"type", "Polygon"}, {"coordinates", small}}}}}}};
  const std::string path = test::scratchPath("keep_in_fence.geojson");
  std::ofstream(path) << fc.dump();
  const std::vector<airspace::Zone> zones = airspace::loadZones(path, airspace::ZoneFormat::kAuto);
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_TRUE(zones[0].keep_in);
  EXPECT_EQ(airspace::restrictionLabel(zones[0]), "KEEP_IN");
  EXPECT_FALSE(zones[1].keep_in);

  const maps::PlaneFrame frame(maps::deg2rad(lat0), maps::deg2rad(lon0));
  const maps::Terrain flat = maps::Terrain::flat(0.0);
  const Obstructions ob = loadObstructions({{path}, airspace::ZoneFormat::kAuto, ""}, frame, flat, {}, {});
  ASSERT_EQ(ob.keepInVolumes().size(), 1u);
  const maps::GpsTime t = *maps::parseRfc3339("2024-05-01T10:00:00Z");
  const Corridor l1({{-150, 0, 100}, {150, 0, 100}}, {5, 5});
  const Corridor l2({{-150, 0, 100}, {150, 0, 100}}, {500, 500});

  // Well inside the fence, clear of the crane's zone (it starts 50 m east).
  FenceVerdict v = checkVolume(l1, l2, ob, {t, t, {{-100, 0, 100}, 3, 3}}, 1000.0);
  ASSERT_GE(v.checks.size(), 3u);
  EXPECT_EQ(v.checks[2].level, Level::kKeepIn);
  EXPECT_EQ(v.checks[2].verdict, Verdict::kInside);
  const double west_m = -frame.toPlane(maps::deg2rad(lat0), maps::deg2rad(lon0 - dlon)).x();  // the square's west edge
  EXPECT_NEAR(v.checks[2].margin_h_m, west_m - 100.0 - 3.0, 0.01);
  json j = v;
  EXPECT_EQ(j["checks"][2]["verdict"], "inside");
  EXPECT_EQ(j["checks"][2]["restriction"], "KEEP_IN");
  EXPECT_EQ(j["checks"][3]["level"], "zone");
  EXPECT_EQ(j["checks"][3]["verdict"], "clear");
  EXPECT_EQ(j["checks"][3]["name"], "crane");
  EXPECT_EQ(j["checks"][3]["restriction"], "PROHIBITED");
  EXPECT_EQ(j.get<FenceVerdict>().checks[3].verdict, Verdict::kInside);  // reads back

  // In the crane's zone: met.
  v = checkVolume(l1, l2, ob, {t, t, {{75, 0, 100}, 3, 3}}, 1000.0);
  j = v;
  EXPECT_EQ(j["violated"], "zone");
  EXPECT_EQ(j["checks"][3]["verdict"], "met");

  // Out of the fence (the corridor is made long enough to hold it): outside the keep-in level.
  const Corridor long1({{-400, 0, 100}, {400, 0, 100}}, {5, 5});
  const Corridor long2({{-400, 0, 100}, {400, 0, 100}}, {500, 500});
  v = checkVolume(long1, long2, ob, {t, t, {{-300, 0, 100}, 3, 3}}, 1000.0);
  EXPECT_EQ(v.verdict, Verdict::kOutside);
  ASSERT_TRUE(v.violated);
  EXPECT_EQ(*v.violated, Level::kKeepIn);
  EXPECT_NEAR(v.checks[*v.deciding].margin_h_m, -(300.0 - west_m) - 3.0, 0.01);
  ASSERT_TRUE(ob.firstConflict({t, t, {{-300, 0, 100}, 3, 3}}));
  EXPECT_FALSE(ob.firstConflict({t, t, {{-300, 0, 100}, 3, 3}}, /*with_keep_in=*/false));
  // The yes/no form agrees: out of the fence, in the crane's zone, and clear inside.
  EXPECT_TRUE(ob.conflicts({t, t, {{-300, 0, 100}, 3, 3}}));
  EXPECT_FALSE(ob.conflicts({t, t, {{-300, 0, 100}, 3, 3}}, /*with_keep_in=*/false));
  EXPECT_TRUE(ob.conflicts({t, t, {{75, 0, 100}, 3, 3}}));
  EXPECT_TRUE(ob.conflicts({t, t, {{75, 0, 100}, 3, 3}}, /*with_keep_in=*/false));
  EXPECT_FALSE(ob.conflicts({t, t, {{-100, 0, 100}, 3, 3}}));
}

}  // namespace
}  // namespace skylane::geofence
