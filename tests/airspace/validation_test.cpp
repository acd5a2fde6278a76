// Validation and repair (CGAL), applicability at instants and over intervals, and the exact
// point-in-zone predicate.

#include "airspace/applicability.hpp"
#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "airspace/zone_geometry.hpp"
#include "maps/geodesy.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <random>
#include <nlohmann/json.hpp>

namespace skylane::airspace {
namespace {

using nlohmann::json;

Zone polygonZone(const std::vector<std::pair<double, double>>& lon_lat_deg, bool keep_in = false) {
  Zone z;
  z.identifier = "T";
  z.source = "test";
  z.feature = "zone";
  z.keep_in = keep_in;
  Volume v;
  for (const auto& [lon, lat] : lon_lat_deg) v.outline.ring.push_back({maps::deg2rad(lat), maps::deg2rad(lon)});
  v.lower.value_m = 0;
  v.upper.value_m = 120;
  z.volumes.push_back(v);
  return z;
}

LatLon at(double lat_deg, double lon_deg) { return {maps::deg2rad(lat_deg), maps::deg2rad(lon_deg)}; }

TEST(ZoneValidation, EdgeTable) {
  struct Case {
    const char* name;
    std::vector<std::pair<double, double>> ring;
    bool ok;
    const char* message;  // substring of the first issue's text
    std::size_t vertices_after;
  };
  const Case cases[] = {
      {"square, closed, ccw", {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}}, true, "", 4},
      {"clockwise is reversed", {{0, 0}, {0, 1}, {1, 1}, {1, 0}}, true, "clockwise ring reversed", 4},
      {"duplicate vertices removed", {{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 0}}, true, "repeated vertex removed", 3},
      {"collinear vertex kept", {{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 0}}, true, "", 4},
      {"two distinct vertices", {{0, 0}, {1, 0}, {1, 0}, {0, 0}}, false, "fewer than 3 distinct vertices (2)", 2},
      {"bow tie", {{0, 0}, {1, 1}, {1, 0}, {0, 1}, {0, 0}}, false, "self-intersecting ring: edge from vertex 0", 4},
      {"spike folding back", {{0, 0}, {2, 0}, {1, 0}, {1, 1}}, false, "self-intersecting ring", 4},
      {"round the north pole", {{0, 80}, {120, 80}, {-120, 80}}, false, "goes round a pole", 3},
      {"across the antimeridian", {{179.5, 10}, {-179.5, 10}, {-179.5, 11}, {179.5, 11}}, true,
       "crosses the antimeridian", 4},
  };
  for (const Case& c : cases) {
    std::vector<Zone> zones{polygonZone(c.ring)};
    const ValidationReport r = validateZones(zones, /*repair=*/false);
    EXPECT_EQ(r.ok(), c.ok) << c.name;
    if (*c.message) {
      const auto found = std::find_if(r.issues.begin(), r.issues.end(),
                                      [&](const ZoneIssue& i) { return i.message.find(c.message) != std::string::npos; });
      ASSERT_NE(found, r.issues.end()) << c.name;
      EXPECT_EQ(found->message.rfind("test: zone (T), volume 0", 0), 0u) << found->message;
    } else {
      EXPECT_TRUE(r.issues.empty()) << c.name << ": " << r.issues[0].message;
    }
    EXPECT_EQ(zones[0].volumes[0].outline.ring.size(), c.vertices_after) << c.name;
  }
}

TEST(ZoneValidation, BowTieRepairIsASupersetAndKeepInIsNotRepaired) {
  // GIVEN the bow tie (0,0)-(1,1)-(1,0)-(0,1): two triangles meeting at (0.5, 0.5)
  const std::vector<std::pair<double, double>> bowtie{{0, 0}, {1, 1}, {1, 0}, {0, 1}, {0, 0}};
  std::vector<Zone> zones{polygonZone(bowtie)};
  // WHEN repaired
  const ValidationReport r = validateZones(zones, /*repair=*/true);
  // THEN it is valid, the report says what was done, and the new ring (the outer boundary of
  // both triangles: 6 vertices, with the crossing point twice) holds both triangles' insides.
  EXPECT_TRUE(r.ok());
  ASSERT_FALSE(r.issues.empty());
  EXPECT_TRUE(r.issues[0].repaired);
  EXPECT_NE(r.issues[0].message.find("repaired"), std::string::npos);
  const Outline& o = zones[0].volumes[0].outline;
  EXPECT_EQ(o.ring.size(), 6u);
  EXPECT_EQ(horizontalSide(o, at(0.5, 0.1)), Side::kInside);   // bottom triangle
  EXPECT_EQ(horizontalSide(o, at(0.5, 0.9)), Side::kInside);   // top triangle
  EXPECT_EQ(horizontalSide(o, at(0.1, 0.5)), Side::kOutside);  // the notch between them
  // A keep-in zone must not grow: the error stays.
  std::vector<Zone> keep{polygonZone(bowtie, /*keep_in=*/true)};
  const ValidationReport k = validateZones(keep, /*repair=*/true);
  EXPECT_FALSE(k.ok());
  EXPECT_NE(k.firstError()->message.find("keep-in zones are not repaired"), std::string::npos);
}

TEST(ZoneValidation, FloorAboveCeilingIsAnErrorAndLoadZonesThrowsNamingTheVertex) {
  std::vector<Zone> zones{polygonZone({{0, 0}, {1, 0}, {1, 1}})};
  zones[0].volumes[0].lower = {200, VerticalReference::kAgl, false, "200 M AGL"};
  zones[0].volumes[0].upper = {120, VerticalReference::kAgl, false, "120 M AGL"};
  const ValidationReport r = validateZones(zones, true);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.firstError()->message.find("floor 200 M AGL is above the ceiling 120 M AGL"), std::string::npos);

  try {
    (void)loadZones(test::dataPath("geozones/bowtie_ed269.json"));
    FAIL() << "no error";
  } catch (const maps::ParseError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bowtie_ed269.json: field 'UASZoneList[0](BOWTIE).volume[0].vertex[0]'"), std::string::npos)
        << what;
    EXPECT_NE(what.find("self-intersecting ring"), std::string::npos) << what;
  }
  EXPECT_EQ(loadZones(test::dataPath("geozones/bowtie_ed269.json"), ZoneFormat::kAuto, /*repair=*/true).size(), 1u);
}

TEST(ZoneGeometry, PointInZoneEdgesAndCircles) {
  const Outline square = polygonZone({{0, 0}, {1, 0}, {1, 1}, {0, 1}}).volumes[0].outline;
  EXPECT_EQ(horizontalSide(square, at(0.5, 0.5)), Side::kInside);
  EXPECT_EQ(horizontalSide(square, at(1.5, 0.5)), Side::kOutside);
  EXPECT_EQ(horizontalSide(square, at(0.0, 0.0)), Side::kBoundary);  // a vertex is on the boundary
  // Circle: 1000 m around (46, 7); a degree of latitude there is 111,151 m (WGS-84 meridian
  // radius of curvature M = a(1−e²)/(1−e² sin²φ)^{3/2}), so 0.00895° north is 994.8 m (inside)
  // and 0.00905° is 1005.9 m (outside).
  Outline c;
  c.kind = Outline::Kind::kCircle;
  c.centre = at(46, 7);
  c.radius_m = 1000;
  EXPECT_EQ(horizontalSide(c, at(46.00895, 7)), Side::kInside);
  EXPECT_EQ(horizontalSide(c, at(46.00905, 7)), Side::kOutside);
  // A zone across the antimeridian contains points on both sides of it.
  std::vector<Zone> z{polygonZone({{179.5, 10}, {-179.5, 10}, {-179.5, 11}, {179.5, 11}})};
  ASSERT_TRUE(validateZones(z, false).ok());
  EXPECT_EQ(horizontalSide(z[0].volumes[0].outline, at(10.5, 179.9)), Side::kInside);
  EXPECT_EQ(horizontalSide(z[0].volumes[0].outline, at(10.5, -179.9)), Side::kInside);
  EXPECT_EQ(horizontalSide(z[0].volumes[0].outline, at(10.5, 179.0)), Side::kOutside);
  // Near the pole: a band 89.5°–89.7° N between 10° and 20° E.
  std::vector<Zone> n{polygonZone({{10, 89.5}, {20, 89.5}, {20, 89.7}, {10, 89.7}})};
  ASSERT_TRUE(validateZones(n, false).ok());
  EXPECT_EQ(horizontalSide(n[0].volumes[0].outline, at(89.6, 15)), Side::kInside);
  EXPECT_EQ(horizontalSide(n[0].volumes[0].outline, at(89.6, 25)), Side::kOutside);
}

maps::GpsTime utc(const char* text) { return *maps::parseRfc3339(text); }

TEST(ZoneApplicability, ScheduleEdgesMidnightAndWeekdays) {
  // Saturday 22:00–02:00 local at +01:00 = Saturday 21:00Z – Sunday 01:00Z, in 2026.
  const auto zones = loadZones(test::dataPath("geozones/plain_zones.geojson"));
  const Zone& market = zones[1];
  EXPECT_FALSE(isActive(market, utc("2026-06-13T20:59:59Z")));  // 2026-06-13 is a Saturday
  EXPECT_TRUE(isActive(market, utc("2026-06-13T21:00:00Z")));   // start inclusive
  EXPECT_TRUE(isActive(market, utc("2026-06-14T00:59:59Z")));   // across midnight
  EXPECT_FALSE(isActive(market, utc("2026-06-14T01:00:00Z")));  // end exclusive
  EXPECT_FALSE(isActive(market, utc("2026-06-14T21:30:00Z")));  // Sunday evening
  EXPECT_FALSE(isActive(market, utc("2027-01-02T21:30:00Z")));  // a Saturday after the end date
  EXPECT_TRUE(isActiveDuring(market, utc("2026-06-10T00:00:00Z"), utc("2026-06-20T00:00:00Z")));
  EXPECT_FALSE(isActiveDuring(market, utc("2026-06-14T01:00:00Z"), utc("2026-06-20T21:00:00Z")));
  EXPECT_TRUE(isActiveDuring(market, utc("2026-06-14T01:00:00Z"), utc("2026-06-20T21:00:01Z")));

  const auto che = loadZones(test::dataPath("geozones/geo-awareness-che-1.json"));
  const Zone& concert = che[0];  // SAT, SUN 17:00Z–23:59:59Z, 2022-06-15T09:00Z – 2023-06-15T09:00Z
  EXPECT_TRUE(isActive(concert, utc("2022-06-18T17:00:00Z")));
  EXPECT_TRUE(isActive(concert, utc("2022-06-19T23:59:59.5Z")));  // "23:59:59" read as midnight
  EXPECT_FALSE(isActive(concert, utc("2022-06-20T17:30:00Z")));   // Monday
  EXPECT_FALSE(isActive(concert, utc("2022-06-11T18:00:00Z")));   // Saturday before the start date
  const Zone& reichenbach = che[1];  // no schedule: the date range alone
  EXPECT_TRUE(isActive(reichenbach, utc("2022-06-15T09:00:00Z")));
  EXPECT_FALSE(isActive(reichenbach, utc("2023-06-15T09:00:00Z")));
  EXPECT_TRUE(isActive(che[2], utc("1999-01-01T00:00:00Z")));  // permanent
}

TEST(ZoneApplicability, AZoneIsAlwaysActiveOnlyWhenSomeEntryHasNeitherDatesNorSchedule) {
  // GIVEN the CHE file's zones (a scheduled one, a dated one, a permanent one) and the GeoJSON
  // file's market (scheduled), and made-up zones: no entry; a dated entry beside a permanent one
  const auto che = loadZones(test::dataPath("geozones/geo-awareness-che-1.json"));
  const auto plain = loadZones(test::dataPath("geozones/plain_zones.geojson"));
  Zone none;
  Zone dated_and_permanent = che[1];
  dated_and_permanent.applicability.push_back(Applicability{});
  Zone permanent_with_schedule = che[2];
  ASSERT_FALSE(permanent_with_schedule.applicability.empty());
  permanent_with_schedule.applicability[0].schedule = che[0].applicability[0].schedule;
  // THEN only those with an entry that is permanent and unscheduled (or no entry) always apply
  EXPECT_FALSE(isAlwaysActive(che[0]));
  EXPECT_FALSE(isAlwaysActive(che[1]));
  EXPECT_TRUE(isAlwaysActive(che[2]));
  EXPECT_FALSE(isAlwaysActive(plain[1]));
  EXPECT_TRUE(isAlwaysActive(none));
  EXPECT_TRUE(isAlwaysActive(dated_and_permanent));
  EXPECT_FALSE(isAlwaysActive(permanent_with_schedule));
  // AND an always-active zone is active at and over any time the rules evaluate: instants and
  // intervals from 1980 to 2100, of zero length up to years, and reversed
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double span_s = 120.0 * 365.25 * 86400.0;
  for (int i = 0; i < 2000; ++i) {
    const maps::GpsTime t0 = maps::GpsTime::fromTotalSeconds(span_s * u(rng));
    const maps::GpsTime t1 = maps::GpsTime::fromTotalSeconds(t0.totalSeconds() + (u(rng) - 0.1) * 86400.0 * std::pow(10.0, 4.0 * u(rng)));
    for (const Zone* z : std::initializer_list<const Zone*>{&che[2], &none, &dated_and_permanent}) {
      ASSERT_TRUE(isActive(*z, t0)) << t0.totalSeconds();
      ASSERT_TRUE(isActiveDuring(*z, t0, t1)) << t0.totalSeconds() << " " << t1.totalSeconds();
    }
  }
}

TEST(ZoneApplicability, TimeOfDayParsing) {
  EXPECT_EQ(parseTimeOfDay("17:00:00.00Z"), 61200.0);
  EXPECT_EQ(parseTimeOfDay("16:00Z"), 57600.0);
  EXPECT_EQ(parseTimeOfDay("01:00+02:00"), -3600.0);
  EXPECT_EQ(parseTimeOfDay("23:00-02:00"), 90000.0);
  EXPECT_EQ(parseTimeOfDay("24:00Z"), 86400.0);
  for (const char* bad : {"", "7:00Z", "17:00", "25:00Z", "12:60Z", "12:00:61Z", "24:01Z", "12:00+1:00", "12:00:00.Z"}) {
    EXPECT_FALSE(parseTimeOfDay(bad).has_value()) << bad;
  }
}

}  // namespace
}  // namespace skylane::airspace
