// Zone loaders: every shared sample, the ED-269 quirks, ED-318 layers and circles, plain
// GeoJSON, QGroundControl fences, and error messages that name the file, zone and field.

#include "airspace/loaders.hpp"
#include "airspace/validation.hpp"
#include "maps/geodesy.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace skylane::airspace {
namespace {

using nlohmann::json;
constexpr double kDegTol = 1e-12;  // degrees survive the radian round trip to ~1e-14

double latDeg(const LatLon& p) { return maps::rad2deg(p.lat_rad); }
double lonDeg(const LatLon& p) { return maps::rad2deg(p.lon_rad); }

TEST(ZoneLoaders, EverySharedSampleLoadsAndValidates) {
  struct Case {
    const char* file;
    ZoneFormat format;
    std::size_t zones;
  };
  for (const Case& c : {Case{"geozones/cis_source_sample_ed269.json", ZoneFormat::kEd269, 1},
                        Case{"geozones/cis_source_sample_ed318.json", ZoneFormat::kEd318, 3},
                        Case{"geozones/geo-awareness-che-1.json", ZoneFormat::kEd269, 6},
                        Case{"geozones/qgc_fence.plan", ZoneFormat::kQgcPlan, 3},
                        Case{"geozones/plain_zones.geojson", ZoneFormat::kGeoJson, 3}}) {
    const json doc = json::parse(test::readData(c.file));
    EXPECT_EQ(detectZoneFormat(doc), c.format) << c.file;
    std::vector<Zone> zones;
    ASSERT_NO_THROW(zones = loadZones(test::dataPath(c.file))) << c.file;
    EXPECT_EQ(zones.size(), c.zones) << c.file;
  }
}

TEST(ZoneLoaders, Ed269StringAndNullLimitsAndEmptyDailyPeriod) {
  const auto zones = readZoneFile(test::dataPath("geozones/cis_source_sample_ed269.json"));
  ASSERT_EQ(zones.size(), 1u);
  const Zone& z = zones[0];
  EXPECT_EQ(z.identifier, "LSXX");
  EXPECT_EQ(z.restriction, Restriction::kReqAuthorisation);
  ASSERT_EQ(z.volumes.size(), 1u);
  EXPECT_FALSE(z.volumes[0].lower.unlimited);  // "lowerLimit": "0"
  EXPECT_EQ(z.volumes[0].lower.value_m, 0.0);
  EXPECT_EQ(z.volumes[0].lower.reference, VerticalReference::kAgl);
  EXPECT_TRUE(z.volumes[0].upper.unlimited);  // "upperLimit": null
  ASSERT_EQ(z.applicability.size(), 1u);
  EXPECT_TRUE(z.applicability[0].permanent);
  ASSERT_EQ(z.applicability[0].schedule.size(), 1u);  // dailyPeriod with day [] and null times
  EXPECT_EQ(z.applicability[0].schedule[0].days, 0x7fu);
  EXPECT_EQ(z.applicability[0].schedule[0].start_s, 0.0);
  EXPECT_EQ(z.applicability[0].schedule[0].end_s, 86400.0);
  ASSERT_EQ(z.volumes[0].outline.ring.size(), 5u);  // as read: closing vertex still there
  EXPECT_NEAR(lonDeg(z.volumes[0].outline.ring[0]), 6.166485701899006, kDegTol);
  EXPECT_NEAR(latDeg(z.volumes[0].outline.ring[0]), 46.217024450605436, kDegTol);
}

TEST(ZoneLoaders, Che1CirclesFeetRepeatedVerticesAndSchedules) {
  const auto zones = loadZones(test::dataPath("geozones/geo-awareness-che-1.json"));
  // Montreux: a 3000 m circle, floor AGL, ceiling AMSL, SAT+SUN 17:00Z–23:59:59Z (read as 24:00).
  const Zone& montreux = zones[0];
  ASSERT_EQ(montreux.volumes[0].outline.kind, Outline::Kind::kCircle);
  EXPECT_EQ(montreux.volumes[0].outline.radius_m, 3000.0);
  EXPECT_NEAR(lonDeg(montreux.volumes[0].outline.centre), 6.913146, kDegTol);
  EXPECT_EQ(montreux.volumes[0].upper.reference, VerticalReference::kAmsl);
  EXPECT_EQ(montreux.volumes[0].upper.value_m, 6259.0);
  const DailyPeriod& p = montreux.applicability.at(0).schedule.at(0);
  EXPECT_EQ(p.days, (1u << 5) | (1u << 6));
  EXPECT_EQ(p.start_s, 17 * 3600.0);
  EXPECT_EQ(p.end_s, 86400.0);
  // Reichenbach: three concentric rings.
  EXPECT_EQ(zones[1].volumes.size(), 3u);
  EXPECT_EQ(zones[1].volumes[2].outline.radius_m, 3500.0);
  EXPECT_EQ(zones[1].volumes[2].lower.value_m, 100.0);
  // Lausanne: repeated vertices removed → triangles, counter-clockwise.
  EXPECT_EQ(zones[2].volumes[1].outline.ring.size(), 3u);
  // Gantrisch: 250 ft AGL = 76.2 m.
  EXPECT_NEAR(zones[4].volumes[0].upper.value_m, 250 * 0.3048, 1e-12);
  EXPECT_EQ(zones[4].volumes[0].upper.as_given, "250 FT AGL");
  EXPECT_EQ(zones[4].restriction, Restriction::kNoRestriction);
}

TEST(ZoneLoaders, Ed318LayerWith99999IsUnlimitedAndTextsArePicked) {
  const auto zones = loadZones(test::dataPath("geozones/cis_source_sample_ed318.json"));
  ASSERT_EQ(zones.size(), 3u);
  EXPECT_EQ(zones[0].identifier, "LSZB003");
  EXPECT_EQ(zones[0].name, "LSZB Bern-Belp 2");
  EXPECT_EQ(zones[0].restriction, Restriction::kReqAuthorisation);  // REQ_AUTHORIZATION
  EXPECT_EQ(zones[0].volumes[0].lower.value_m, 60.0);
  EXPECT_TRUE(zones[0].volumes[0].upper.unlimited);
  EXPECT_EQ(zones[1].name, "Protected natural object Langmatt");  // en-GB of four languages
  EXPECT_TRUE(zones[0].applicability.empty());
}

TEST(ZoneLoaders, Ed318CircleGeometryCollectionAndLimitedApplicability) {
  const json doc = json::parse(R"({"type":"FeatureCollection","features":[{"type":"Feature",
    "properties":{"identifier":"C1","country":"CHE","type":"PROHIBITED","variant":"COMMON","zoneAuthority":[],
      "limitedApplicability":[{"startDateTime":"2026-01-01T00:00:00Z","endDateTime":"2026-02-01T00:00:00Z",
        "schedule":[{"day":["MON"],"startTime":"08:00:00Z","endEvent":"SS"}]}]},
    "geometry":{"type":"GeometryCollection","geometries":[
      {"type":"Point","coordinates":[8.5,47.4],"extent":{"subType":"Circle","radius":3500},
       "layer":{"upper":500,"upperReference":"AMSL","lower":0,"lowerReference":"AGL","uom":"ft"}},
      {"type":"Polygon","coordinates":[[[8.0,47.0],[8.1,47.0],[8.1,47.1],[8.0,47.0]]],
       "layer":{"upper":99999,"upperReference":"AMSL","lower":150,"lowerReference":"AMSL","uom":"m"}}]}}]})");
  const auto zones = parseZones(doc, "mem.json");
  ASSERT_EQ(zones.size(), 1u);
  ASSERT_EQ(zones[0].volumes.size(), 2u);
  EXPECT_EQ(zones[0].volumes[0].outline.kind, Outline::Kind::kCircle);
  EXPECT_EQ(zones[0].volumes[0].outline.radius_m, 3500.0);
  EXPECT_NEAR(zones[0].volumes[0].upper.value_m, 152.4, 1e-9);
  EXPECT_TRUE(zones[0].volumes[1].upper.unlimited);
  const DailyPeriod& p = zones[0].applicability.at(0).schedule.at(0);
  EXPECT_TRUE(p.approximated);  // sunset event → whole day, on the safe side
  EXPECT_EQ(p.start_s, 0.0);
  EXPECT_EQ(p.end_s, 86400.0);
  ASSERT_EQ(zones[0].notes.size(), 1u);
  EXPECT_NE(zones[0].notes[0].find("endEvent"), std::string::npos);
}

TEST(ZoneLoaders, QgcFenceIsLatitudeFirstWithInclusionAsKeepIn) {
  const auto zones = loadZones(test::dataPath("geozones/qgc_fence.plan"));
  ASSERT_EQ(zones.size(), 3u);
  EXPECT_TRUE(zones[0].keep_in);
  EXPECT_EQ(restrictionLabel(zones[0]), "KEEP_IN");  // what zones validate / at / export say
  EXPECT_FALSE(zones[1].keep_in);
  EXPECT_EQ(restrictionLabel(zones[1]), "PROHIBITED");
  EXPECT_NEAR(latDeg(zones[1].volumes[0].outline.ring[0]), 46.53, kDegTol);
  EXPECT_NEAR(lonDeg(zones[1].volumes[0].outline.ring[0]), 6.60, kDegTol);
  EXPECT_EQ(zones[2].volumes[0].outline.radius_m, 250.0);
  EXPECT_NEAR(latDeg(zones[2].volumes[0].outline.centre), 46.56, kDegTol);
  EXPECT_TRUE(zones[2].volumes[0].lower.unlimited);
  EXPECT_TRUE(zones[2].volumes[0].upper.unlimited);
}

TEST(ZoneLoaders, PlainGeoJsonAntimeridianFeetCircleAndMultiPolygon) {
  const auto zones = loadZones(test::dataPath("geozones/plain_zones.geojson"));
  ASSERT_EQ(zones.size(), 3u);
  // The ring across ±180° has continuous longitudes after validation: 179.9 … 180.1.
  const auto& ring = zones[0].volumes[0].outline.ring;
  ASSERT_EQ(ring.size(), 4u);
  double min_lon = 1e9, max_lon = -1e9;
  for (const LatLon& p : ring) {
    min_lon = std::min(min_lon, lonDeg(p));
    max_lon = std::max(max_lon, lonDeg(p));
  }
  EXPECT_NEAR(max_lon - min_lon, 0.2, 1e-9);
  EXPECT_NEAR(zones[0].volumes[0].upper.value_m, 400 * 0.3048, 1e-12);
  EXPECT_EQ(zones[1].volumes[0].outline.kind, Outline::Kind::kCircle);
  EXPECT_EQ(zones[1].volumes[0].outline.radius_m, 300.0);
  EXPECT_TRUE(zones[1].volumes[0].lower.unlimited);  // no lower: no floor
  EXPECT_EQ(zones[2].volumes.size(), 2u);
  EXPECT_EQ(zones[2].volumes[0].lower.reference, VerticalReference::kWgs84);
  EXPECT_EQ(zones[2].restriction, Restriction::kProhibited);  // defaulted, with a note
  EXPECT_FALSE(zones[2].notes.empty());
}

TEST(ZoneLoaders, ErrorsNameFileZoneFieldAndExpectation) {
  struct Case {
    const char* name;
    const char* doc;
    const char* expected;
  };
  const Case cases[] = {
      {"bad restriction",
       R"({"UASZoneList":[{"identifier":"Z1","restriction":"FORBIDDEN","geometry":[]}]})",
       "mem.json: field 'UASZoneList[0](Z1).restriction': got 'FORBIDDEN', expected PROHIBITED"},
      {"latitude out of range",
       R"({"UASZoneList":[{"identifier":"Z2","restriction":"PROHIBITED","geometry":[{"uomDimensions":"M",
          "lowerLimit":0,"lowerVerticalReference":"AGL","upperLimit":100,"upperVerticalReference":"AGL",
          "horizontalProjection":{"type":"Polygon","coordinates":[[[6,46],[6,95],[7,46],[6,46]]]}}]}]})",
       "UASZoneList[0](Z2).geometry[0].horizontalProjection.coordinates[0][1][1]': got '95', expected a latitude"},
      {"NaN-like string limit",
       R"({"UASZoneList":[{"identifier":"Z3","restriction":"PROHIBITED","geometry":[{"uomDimensions":"M",
          "lowerLimit":"low","lowerVerticalReference":"AGL","upperLimit":100,"upperVerticalReference":"AGL",
          "horizontalProjection":{"type":"Circle","center":[6,46],"radius":10}}]}]})",
       "geometry[0].lowerLimit': got 'low', expected a number, a numeric string or null"},
      {"unknown unit",
       R"({"UASZoneList":[{"identifier":"Z4","restriction":"PROHIBITED","geometry":[{"uomDimensions":"NM",
          "lowerLimit":0,"lowerVerticalReference":"AGL","upperLimit":100,"upperVerticalReference":"AGL",
          "horizontalProjection":{"type":"Circle","center":[6,46],"radius":10}}]}]})",
       "geometry[0].uomDimensions': got 'NM', expected M or FT"},
      {"bad weekday",
       R"({"UASZoneList":[{"identifier":"Z5","restriction":"PROHIBITED","applicability":[{"permanent":"NO",
          "schedule":[{"day":["FUNDAY"],"startTime":"10:00Z","endTime":"11:00Z"}]}],"geometry":[]}]})",
       "applicability[0].schedule[0].day[0]': got 'FUNDAY', expected MON"},
      {"holes", R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon",
          "coordinates":[[[0,0],[1,0],[1,1],[0,0]],[[0.1,0.1],[0.2,0.1],[0.2,0.2],[0.1,0.1]]]}}]})",
       "features[0].geometry.coordinates[1]': got '[[0.1,0.1],[0.2,0.1],[0.2,0.2],[0.1,0.1]]', expected no interior rings"},
      {"not a zone file", R"({"hello":1})", "mem.json: field '(format)'"},
  };
  for (const Case& c : cases) {
    try {
      (void)parseZones(json::parse(c.doc), "mem.json");
      ADD_FAILURE() << c.name << ": no error";
    } catch (const maps::ParseError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << c.name << ": " << e.what();
    }
  }
}

TEST(ZoneLoaders, JsonSyntaxErrorNamesTheLine) {
  const std::string path = test::scratchPath("broken_zones.json");
  {
    std::ofstream f(path);
    f << "{\n  \"UASZoneList\": [\n    {\"identifier\": \"X\",,}\n  ]\n}\n";
  }
  try {
    (void)readZoneFile(path);
    FAIL() << "no error";
  } catch (const maps::ParseError& e) {
    EXPECT_EQ(e.line(), 3) << e.what();
    EXPECT_NE(std::string(e.what()).find(path + ":3"), std::string::npos) << e.what();
  }
}

// Plain GeoJSON keep-in zones: restriction KEEP_IN or keep_in: true; ED-318 has no such type.
TEST(ZoneLoaders, GeoJsonKeepInByRestrictionOrProperty) {
  auto feature = [](const json& props) {
    return json{{"type", "FeatureCollection"},
                {"features", {{{"type", "Feature"},
                               {"properties", props},
                               {"geometry", {{"type", "Point"}, {"coordinates", {8.5, 47.3}}}}}}}};
  };
  const auto by_word = parseZones(feature({{"restriction", "KEEP_IN"}, {"radius_m", 100}}), "mem.json");
  ASSERT_EQ(by_word.size(), 1u);
  EXPECT_TRUE(by_word[0].keep_in);
  const auto by_flag = parseZones(feature({{"keep_in", true}, {"radius_m", 100}}), "mem.json");
  EXPECT_TRUE(by_flag[0].keep_in);
  EXPECT_TRUE(by_flag[0].notes.empty());  // not "taken as PROHIBITED"
  try {
    (void)parseZones(feature({{"restriction", "KEEPIN"}, {"radius_m", 100}}), "mem.json");
    FAIL() << "an unknown restriction was accepted";
  } catch (const maps::ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("KEEP_IN"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("properties.restriction"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace skylane::airspace
