// Buildings: GeoJSON footprints and heights → prisms and closed meshes (maps/buildings.hpp).
#include "maps/buildings.hpp"

#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "maps/parse_error.hpp"
#include "tests/maps/raster_fixture.hpp"
#include "tests/test_util.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <map>
#include <set>

namespace skylane::maps {
namespace {

/// Heights to the millimetre, where nothing conservative widens them.
constexpr double kHeightTol_m = 1e-3;
/// The geoid's conservative range over a footprint's box (Geoid::undulationRange_m: the extremes
/// of the grid nodes interpolation can use) widens the prism: the base goes down, the top up,
/// by up to the undulation's spread over one 15' cell (decimetres).
constexpr double kGeoidSpread_m = 0.5;
/// ENU ⇄ geodetic round trips are exact to nanometres; the mesh sums a few hundred products.
constexpr double kGeomTol_m = 1e-6;

const Geodetic kOrigin{deg2rad(47.3769), deg2rad(8.5417), 0.0};  // Zürich

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = test::scratchPath(name);
  std::ofstream(path) << text;
  return path;
}

/// A GeoJSON [lon, lat] pair of the point at (e, n) metres from kOrigin.
std::string lonLat(double e_m, double n_m) {
  const Geodetic g = LocalFrame(kOrigin).fromEnu({e_m, n_m, 0.0});
  char buf[80];
  std::snprintf(buf, sizeof buf, "[%.10f,%.10f]", rad2deg(g.lon_rad), rad2deg(g.lat_rad));
  return buf;
}

/// A rectangle footprint [e0, e1] × [n0, n1] as a closed GeoJSON ring, counter-clockwise.
std::string rectRing(double e0, double n0, double e1, double n1) {
  return "[" + lonLat(e0, n0) + "," + lonLat(e1, n0) + "," + lonLat(e1, n1) + "," + lonLat(e0, n1) + "," + lonLat(e0, n0) + "]";
}

std::string feature(const std::string& id, const std::string& geometry, const std::string& props) {
  return R"({"type":"Feature","id":")" + id + R"(","geometry":)" + geometry + R"(,"properties":)" + props + "}";
}

std::string polygon(const std::string& ring) { return R"({"type":"Polygon","coordinates":[)" + ring + "]}"; }

std::string collection(const std::vector<std::string>& features) {
  std::string s = R"({"type":"FeatureCollection","features":[)";
  for (std::size_t i = 0; i < features.size(); ++i) s += (i ? "," : "") + features[i];
  return s + "]}";
}

double geoidHere() { return Geoid::egm96().undulation_m(kOrigin.lat_rad, kOrigin.lon_rad); }

std::vector<Building> parse(const std::string& text, const Terrain& terrain = Terrain::flat(0.0),
                            const BuildingOptions& options = {}) {
  return parseBuildings(nlohmann::json::parse(text), "city.geojson", terrain, options);
}

// --- heights -------------------------------------------------------------------------------

TEST(HeightText, ReadsMetresAndFeetAsOsmWritesThem) {
  const std::vector<std::pair<std::string, double>> cases = {
      {"12", 12.0}, {"12 m", 12.0}, {"12.5m", 12.5}, {" 7 metres", 7.0}, {"40 ft", 40 * 0.3048},
      {"40'", 40 * 0.3048}, {"10 FT", 3.048}, {"0", 0.0}};
  for (const auto& [text, metres] : cases) {
    const auto v = parseHeightText_m(text);
    ASSERT_TRUE(v.has_value()) << text;
    EXPECT_DOUBLE_EQ(*v, metres) << text;
  }
  for (const char* bad : {"", "tall", "12 storeys", "m", "12 m m", "nan"}) EXPECT_FALSE(parseHeightText_m(bad)) << bad;
}

TEST(Buildings, HeightLevelsFeetAndMinHeightBecomeEllipsoidalBaseAndTop) {
  const std::string ring = rectRing(0, 0, 20, 10);
  const auto b = parse(collection({feature("a", polygon(ring), R"({"height":12})"),
                                   feature("b", polygon(ring), R"({"height":"40 ft"})"),
                                   feature("c", polygon(ring), R"({"building:levels":"5"})"),
                                   feature("d", polygon(ring), R"({"levels":4,"min_height":"3 m"})"),
                                   feature("e", polygon(ring), R"({"height":30,"building:min_level":2})"),
                                   feature("f", polygon(ring), R"({"top_amsl_m":420.5})")}),
                       Terrain::flat(408.0));
  ASSERT_EQ(b.size(), 6u);
  const double ground = 408.0 + geoidHere();
  const double expected_top[] = {12.0, 12.192, 15.0, 12.0, 30.0, 12.5};
  const double expected_base[] = {0.0, 0.0, 0.0, 3.0, 6.0, 0.0};
  const auto [n_lo, n_hi] = Geoid::egm96().undulationRange_m(kOrigin.lat_rad, kOrigin.lat_rad + 1e-6, kOrigin.lon_rad,
                                                             kOrigin.lon_rad + 1e-6);
  ASSERT_LT(n_hi - n_lo, kGeoidSpread_m);
  for (std::size_t i = 0; i < b.size(); ++i) {
    // On the safe side of the exact heights, and by no more than the geoid's spread.
    EXPECT_GE(b[i].top_h_ell_m - ground, expected_top[i] - kHeightTol_m) << b[i].feature;
    EXPECT_LE(b[i].top_h_ell_m - ground, expected_top[i] + (n_hi - n_lo) + kHeightTol_m) << b[i].feature;
    EXPECT_LE(b[i].base_h_ell_m - ground, expected_base[i] + kHeightTol_m) << b[i].feature;
    EXPECT_GE(b[i].base_h_ell_m - ground, expected_base[i] - (n_hi - n_lo) - kHeightTol_m) << b[i].feature;
    // The spread enters once per building: top − base is the stated height plus the spread.
    EXPECT_NEAR(b[i].top_h_ell_m - b[i].base_h_ell_m, expected_top[i] - expected_base[i] + (n_hi - n_lo), kHeightTol_m)
        << b[i].feature;
    EXPECT_EQ(b[i].ring_lat_lon_rad.size(), 4u) << "the closing vertex is dropped";
  }
  EXPECT_EQ(b[0].feature, "features[0](a)");
  EXPECT_EQ(b[0].source, "city.geojson");
}

TEST(Buildings, MetresPerLevelAndDefaultHeightAreOptions) {
  const std::string ring = rectRing(0, 0, 20, 10);
  BuildingOptions o;
  o.metres_per_level = 3.5;
  o.default_height_m = 9.0;
  const auto b = parse(collection({feature("a", polygon(ring), R"({"building:levels":4})"),
                                   feature("b", polygon(ring), R"({"building":"yes"})")}),
                       Terrain::flat(0.0), o);
  const auto [n_lo, n_hi] = Geoid::egm96().undulationRange_m(kOrigin.lat_rad, kOrigin.lat_rad + 1e-6, kOrigin.lon_rad,
                                                             kOrigin.lon_rad + 1e-6);
  EXPECT_NEAR(b[0].top_h_ell_m - b[0].base_h_ell_m, 14.0 + (n_hi - n_lo), kHeightTol_m);
  EXPECT_NEAR(b[1].top_h_ell_m - b[1].base_h_ell_m, 9.0 + (n_hi - n_lo), kHeightTol_m);
}

TEST(Buildings, MultiPolygonGivesOneBuildingPerPartAndHolesAreFilled) {
  const std::string hole = rectRing(5, 3, 8, 6);
  const std::string mp = R"({"type":"MultiPolygon","coordinates":[[)" + rectRing(0, 0, 20, 10) + "," + hole + "],[" +
                         rectRing(40, 0, 50, 10) + "]]}";
  const auto b = parse(collection({feature("way/7", mp, R"({"height":10})")}));
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].feature, "features[0](way/7).geometry.coordinates[0]");
  EXPECT_EQ(b[1].feature, "features[0](way/7).geometry.coordinates[1]");
  EXPECT_TRUE(b[0].holes_filled);
  EXPECT_FALSE(b[1].holes_filled);
}

TEST(Buildings, PointObstacleIsACircumscribedPolygonOfItsRadius) {
  const auto b = parse(collection({feature("mast", R"({"type":"Point","coordinates":)" + lonLat(30, 40) + "}",
                                           R"({"height":45,"radius":2.5})"),
                                   feature("pole", R"({"type":"Point","coordinates":)" + lonLat(0, 0) + "}",
                                           R"({"height":"10 m"})")}));
  ASSERT_EQ(b.size(), 2u);
  const LocalFrame frame(kOrigin);
  for (const auto& [building, radius, centre] :
       {std::make_tuple(b[0], 2.5, Eigen::Vector2d(30, 40)), std::make_tuple(b[1], kDefaultObstacleRadius_m, Eigen::Vector2d(0, 0))}) {
    EXPECT_TRUE(building.from_point);
    const Prism p = extrude(building, frame);
    ASSERT_EQ(p.footprint_en.size(), static_cast<std::size_t>(kObstacleSides));
    for (std::size_t i = 0; i < p.footprint_en.size(); ++i) {
      // Every edge touches the circle: its distance from the centre is the radius.
      const Eigen::Vector2d a = p.footprint_en[i] - centre, d = p.footprint_en[(i + 1) % p.footprint_en.size()] - a - centre;
      const double dist = std::abs(a.x() * d.y() - a.y() * d.x()) / d.norm();
      // (to 1 mm: the prism's corners stand at the base height, 48 m above the ellipsoid
      // where the GeoJSON centre was placed; the frame's U axis leans 48 m × 50 m / R = 0.4 mm)
      EXPECT_NEAR(dist, radius, 1e-3) << building.feature << " edge " << i;
    }
  }
}

TEST(Buildings, GroundUnderAFootprintOnASlopeIsTakenOnTheSafeSide) {
  // GIVEN a DEM rising 1 m per cell eastward (cells 0.0001° ≈ 7.5 m east, 11 m north)
  const double lon0 = rad2deg(kOrigin.lon_rad) - 0.01, lat0 = rad2deg(kOrigin.lat_rad) + 0.01;
  const double gt[6] = {lon0, 1e-4, 0, lat0, 0, -1e-4};
  const std::string tif = test::writeGeoTiff("slope.tif", 200, 200, gt, "EPSG:4326", [](int, int c) { return 400.0 + c; });
  const Terrain dem = Terrain::fromRaster(tif);
  // WHEN a 30 m wide building of height 10 m stands on it
  const auto b = parse(collection({feature("x", polygon(rectRing(0, 0, 30, 10)), R"({"height":10})")}), dem);
  ASSERT_EQ(b.size(), 1u);
  // THEN its base is at or below the lowest ground under it, its top 10 m above the highest
  double lo = 1e9, hi = -1e9;
  const LocalFrame frame(kOrigin);
  for (double e = 0; e <= 30; e += 1) {
    for (double n = 0; n <= 10; n += 1) {
      const Geodetic g = frame.fromEnu({e, n, 0});
      const double h = *dem.heightEllipsoid_m(g.lat_rad, g.lon_rad);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  }
  EXPECT_LE(b[0].base_h_ell_m, lo + kHeightTol_m);
  EXPECT_GE(b[0].top_h_ell_m, hi + 10.0 - kHeightTol_m);
  EXPECT_GT(b[0].base_h_ell_m, lo - 2.0 - kGeoidSpread_m) << "no lower than a couple of cells' rise";
  EXPECT_LT(b[0].top_h_ell_m, hi + 10.0 + 2.0 + kGeoidSpread_m);
}

// --- errors name the file, the feature, the field, the value, what was expected -----------

TEST(Buildings, BadFeaturesFailTheLoadWithAMessageNamingFileFeatureFieldAndValue) {
  const std::string ring = rectRing(0, 0, 20, 10);
  const auto msg = [](const std::string& text) {
    const std::string path = writeTemp("bad.geojson", text);
    return test::messageOf<ParseError>([&] { (void)loadBuildings(path, Terrain::flat(0.0)); });
  };
  const std::string p = test::scratchPath("bad.geojson");
  EXPECT_EQ(msg(collection({feature("ok", polygon(ring), R"({"height":5})"), feature("way/2", polygon(ring), R"({"height":"tall"})")})),
            p + ": field 'features[1](way/2).properties.height': got 'tall', expected a height in metres: a number or a "
                "string such as \"12\", \"12 m\" or \"40 ft\", in [0, 2000] m");
  EXPECT_EQ(msg(collection({feature("b", polygon(ring), R"({"name":"no height"})")})),
            p + ": field 'features[0](b).properties.height' is missing, expected a height: 'height' (metres or \"40 ft\"), "
                "'building:levels' / 'levels', or 'top_amsl_m'");
  EXPECT_NE(msg(collection({feature("c", polygon(ring), R"({"height":5,"min_height":8})")})).find("features[0](c).properties.height"),
            std::string::npos);
  EXPECT_NE(msg(collection({feature("d", R"({"type":"LineString","coordinates":[[8,47],[8.1,47]]})", R"({"height":5})")}))
                .find("'features[0](d).geometry.type': got 'LineString', expected Polygon, MultiPolygon or Point"),
            std::string::npos);
  EXPECT_NE(msg(collection({feature("e", R"({"type":"Polygon","coordinates":[[[8,95],[8.1,47],[8,47.1],[8,95]]]})", R"({"height":5})")}))
                .find("'features[0](e).geometry.coordinates[0][0][1]': got '95', expected a latitude in [-90, 90] degrees"),
            std::string::npos);
  // A bow tie with unequal lobes (so that it has an area): edges 0 and 2 cross at (6.7, 6.7).
  const std::string bowtie = "[" + lonLat(0, 0) + "," + lonLat(10, 10) + "," + lonLat(10, 0) + "," + lonLat(0, 20) + "," + lonLat(0, 0) + "]";
  EXPECT_NE(msg(collection({feature("f", polygon(bowtie), R"({"height":5})")})).find("features[0](f).geometry.coordinates[0]'"),
            std::string::npos);
  EXPECT_NE(msg(collection({feature("f", polygon(bowtie), R"({"height":5})")})).find("a simple ring (edges 0 and 2 cross"),
            std::string::npos);
  EXPECT_NE(msg(R"({"type":"FeatureCollection","features":[{"type":"Feature","geometry":{"type":"Polygon","coordinates":[[[8,47],[8,47],[8,47]]]},"properties":{"height":3}}]})")
                .find("features[0].geometry.coordinates[0]"),
            std::string::npos);
  EXPECT_NE(msg("{\"type\":\"FeatureCollection\",\n\"features\":[}").find(p + ":2: field '(JSON syntax)'"), std::string::npos);
  EXPECT_NE(msg(R"([1,2])").find("expected a GeoJSON FeatureCollection of buildings"), std::string::npos);
}

TEST(Buildings, AFootprintOffTheTerrainRasterIsAnErrorNamingTheFeature) {
  const double gt[6] = {0.0, 1e-3, 0, 1.0, 0, -1e-3};  // a raster near (0°, 0°), far from Zürich
  const std::string tif = test::writeGeoTiff("elsewhere.tif", 10, 10, gt, "EPSG:4326", [](int, int) { return 5.0; });
  const std::string m = test::messageOf<ParseError>(
      [&] { (void)parse(collection({feature("z", polygon(rectRing(0, 0, 5, 5)), R"({"height":4})")}), Terrain::fromRaster(tif)); });
  EXPECT_NE(m.find("city.geojson: field 'features[0](z).geometry': got 'a footprint outside the terrain raster or on a void'"),
            std::string::npos)
      << m;
}

// --- prisms and meshes --------------------------------------------------------------------

/// Euler characteristic, edge manifoldness and orientation of a triangle mesh.
struct MeshTopology {
  int v = 0, e = 0, f = 0;
  bool every_edge_twice_opposite = true;
};

MeshTopology topology(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  MeshTopology top;
  std::set<std::pair<int, int>> undirected;
  for (const auto& [edge, count] : directed) {
    undirected.insert({std::min(edge.first, edge.second), std::max(edge.first, edge.second)});
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1) top.every_edge_twice_opposite = false;
  }
  top.v = static_cast<int>(m.vertices_enu.size());
  top.e = static_cast<int>(undirected.size());
  top.f = static_cast<int>(m.triangles.size());
  return top;
}

/// Signed volume by the divergence theorem: Σ a·(b × c) / 6 (positive for outward normals).
double signedVolume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) {
    v += m.vertices_enu[static_cast<std::size_t>(t[0])].dot(
        m.vertices_enu[static_cast<std::size_t>(t[1])].cross(m.vertices_enu[static_cast<std::size_t>(t[2])]));
  }
  return v / 6.0;
}

bool insidePolygon(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[(i + 1) % n];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) in = !in;
  }
  return in;
}

struct NamedFootprint {
  const char* name;
  std::vector<Eigen::Vector2d> ring;
  double area_m2;
};

std::vector<NamedFootprint> footprints() {
  return {
      {"box 20x10", {{0, 0}, {20, 0}, {20, 10}, {0, 10}}, 200.0},
      {"L shape", {{0, 0}, {30, 0}, {30, 10}, {10, 10}, {10, 25}, {0, 25}}, 30 * 10 + 10 * 15},
      {"U shape, clockwise", {{0, 0}, {0, 20}, {5, 20}, {5, 5}, {15, 5}, {15, 20}, {20, 20}, {20, 0}}, 400 - 10 * 15},
      {"collinear vertex", {{0, 0}, {10, 0}, {20, 0}, {20, 10}, {0, 10}}, 200.0},
      {"comb", {{0, 0}, {40, 0}, {40, 30}, {35, 30}, {35, 5}, {25, 5}, {25, 30}, {15, 30}, {15, 5}, {5, 5}, {5, 30}, {0, 30}},
       40 * 5 + 25 * (5 + 10 + 5)},
  };
}

TEST(PrismMesh, IsClosedOutwardAndHoldsFootprintAreaTimesHeight) {
  // Frame invariance: the same footprints shifted and rotated must give the same answers.
  const std::vector<std::pair<double, Eigen::Vector2d>> poses = {{0.0, {0, 0}}, {0.7, {-300, 120}}, {2.9, {1500, -2200}}};
  for (const NamedFootprint& fp : footprints()) {
    for (const auto& [angle, shift] : poses) {
      Prism p;
      const Eigen::Rotation2Dd rot(angle);
      for (const Eigen::Vector2d& q : fp.ring) p.footprint_en.push_back(rot * q + shift);
      p.bottom_u_m = 12.0;
      p.top_u_m = 12.0 + 17.5;
      const TriangleMesh m = prismMesh(p);
      const MeshTopology t = topology(m);
      const int n = static_cast<int>(fp.ring.size());
      SCOPED_TRACE(std::string(fp.name) + " at angle " + std::to_string(angle));
      EXPECT_EQ(t.v, 2 * n);
      EXPECT_EQ(t.f, 4 * n - 4);
      EXPECT_EQ(t.v - t.e + t.f, 2);
      EXPECT_TRUE(t.every_edge_twice_opposite) << "closed and consistently wound";
      EXPECT_NEAR(signedVolume(m), fp.area_m2 * 17.5, kGeomTol_m * fp.area_m2);
      // Each face's normal points out: a step along it from the face's centre leaves the solid.
      std::vector<Eigen::Vector2d> ring;
      for (const Eigen::Vector2d& q : fp.ring) ring.push_back(rot * q + shift);
      for (const auto& tri : m.triangles) {
        const Eigen::Vector3d& a = m.vertices_enu[static_cast<std::size_t>(tri[0])];
        const Eigen::Vector3d& b = m.vertices_enu[static_cast<std::size_t>(tri[1])];
        const Eigen::Vector3d& c = m.vertices_enu[static_cast<std::size_t>(tri[2])];
        const Eigen::Vector3d normal = (b - a).cross(c - a);
        ASSERT_GT(normal.norm(), 0.0) << "degenerate triangle";
        const Eigen::Vector3d out = (a + b + c) / 3.0 + 0.01 * normal.normalized();
        const bool in_solid = out.z() > p.bottom_u_m && out.z() < p.top_u_m && insidePolygon(ring, out.head<2>());
        EXPECT_FALSE(in_solid) << "triangle " << tri[0] << "," << tri[1] << "," << tri[2];
        const Eigen::Vector3d in = (a + b + c) / 3.0 - 0.01 * normal.normalized();
        EXPECT_TRUE(in.z() > p.bottom_u_m && in.z() < p.top_u_m && insidePolygon(ring, in.head<2>()));
      }
    }
  }
}

TEST(EarClip, CoversANonConvexFootprintWithCounterClockwiseTriangles) {
  for (const NamedFootprint& fp : footprints()) {
    std::vector<Eigen::Vector2d> ring = fp.ring;
    if (signedArea2(ring) < 0) std::reverse(ring.begin(), ring.end());
    const auto tris = earClip(ring);
    ASSERT_EQ(tris.size(), ring.size() - 2) << fp.name;
    double area = 0;
    for (const auto& t : tris) {
      const double a2 = signedArea2({ring[static_cast<std::size_t>(t[0])], ring[static_cast<std::size_t>(t[1])],
                                     ring[static_cast<std::size_t>(t[2])]});
      EXPECT_GE(a2, 0.0) << fp.name;
      area += a2 / 2;
    }
    EXPECT_NEAR(area, fp.area_m2, 1e-9 * fp.area_m2) << fp.name;
  }
}

TEST(Extrude, GivesTheFootprintInEnuCounterClockwiseWithTheHeightsInU) {
  // GIVEN a clockwise 20 m × 10 m footprint 500 m east of the frame origin, ground 0 m AMSL
  const std::string cw = "[" + lonLat(500, 0) + "," + lonLat(500, 10) + "," + lonLat(520, 10) + "," + lonLat(520, 0) + "," +
                         lonLat(500, 0) + "]";
  const auto b = parse(collection({feature("a", polygon(cw), R"({"height":25,"min_height":2})")}));
  const Geodetic origin{kOrigin.lat_rad, kOrigin.lon_rad, geoidHere()};  // frame on the geoid
  const Prism p = extrude(b[0], LocalFrame(origin));
  ASSERT_EQ(p.footprint_en.size(), 4u);
  EXPECT_GT(signedArea2(p.footprint_en), 0.0) << "counter-clockwise";
  // (the corners stand 48 m below the frame origin's height, where the frame's metres are
  // (R + 48 m) / R = 1 + 7.5e-6 times the ground's: 3 mm² in 200 m²)
  EXPECT_NEAR(signedArea2(p.footprint_en) / 2, 200.0, 5e-3);
  // The curvature drop at 500 m, 2 cm, is taken on the safe side: bottom lower, top higher.
  const double drop_500 = 500.0 * 500.0 / (2 * 6.39e6), drop_520 = 520.0 * 520.0 / (2 * 6.39e6);
  EXPECT_NEAR(p.bottom_u_m, b[0].base_h_ell_m - origin.h_ell_m - drop_520, 2e-3);
  EXPECT_NEAR(p.top_u_m, b[0].top_h_ell_m - origin.h_ell_m - drop_500, 2e-3);
  EXPECT_LE(b[0].base_h_ell_m - origin.h_ell_m, 2.0 + kHeightTol_m);
}

}  // namespace
}  // namespace skylane::maps
