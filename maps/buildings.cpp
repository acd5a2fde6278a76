#include "maps/buildings.hpp"

#include "maps/geoid.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/plane_frame.hpp"
#include "maps/text_file.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace skylane::maps {
namespace {

using nlohmann::json;

/// Metres per international foot.
constexpr double kMetresPerFoot = 0.3048;
/// Mean Earth radius [m], only to turn degrees into metres for the footprint checks below.
constexpr double kMeanEarthRadius_m = 6371008.8;
/// Smallest footprint area accepted [m²]: below a 10 cm square nothing is left to extrude.
constexpr double kMinFootprintArea_m2 = 0.01;
/// Tallest building or obstacle accepted [m] (the tallest building stands 828 m; a typo in
/// feet or millimetres lands far above).
constexpr double kMaxHeight_m = 2000.0;
/// Most levels accepted.
constexpr double kMaxLevels = 300.0;

using Node = JsonNode;

/// A plain number, or a numeric string (OSM writes `building:levels` as "5").
double numberOrNumericString(const Node& n, const std::string& expected) {
  if (n.j.is_number()) {
    const double v = n.j.get<double>();
    if (!std::isfinite(v)) n.fail(expected);
    return v;
  }
  if (!n.j.is_string()) n.fail(expected);
  const std::string t = n.j.get<std::string>();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v)) n.fail(expected);
  return v;
}

/// A height property: a number of metres or a height text (parseHeightText_m), in [0, kMaxHeight_m].
double heightValue(const Node& n) {
  static const std::string kExpected = "a height in metres: a number or a string such as \"12\", \"12 m\" or \"40 ft\", in [0, 2000] m";
  double v = 0.0;
  if (n.j.is_number()) {
    v = n.number();
  } else if (n.j.is_string()) {
    const auto parsed = parseHeightText_m(n.j.get<std::string>());
    if (!parsed) n.fail(kExpected);
    v = *parsed;
  } else {
    n.fail(kExpected);
  }
  if (!(v >= 0.0 && v <= kMaxHeight_m)) n.fail(kExpected);
  return v;
}

double levelsValue(const Node& n) {
  const double v = numberOrNumericString(n, "a number of levels (a number or a numeric string) in [0, 300]");
  if (!(v >= 0.0 && v <= kMaxLevels)) n.fail("a number of levels in [0, 300]");
  return v;
}

/// [lon, lat] in degrees → (lat, lon) in radians.
std::pair<double, double> position(const Node& n) {
  const json& a = n.array();
  if (a.size() < 2) n.fail("[lon, lat] in degrees");
  const double lon = n.item(0).number();
  const double lat = n.item(1).number();
  if (!(lat >= -90.0 && lat <= 90.0)) n.item(1).fail("a latitude in [-90, 90] degrees");
  if (!(lon >= -180.0 && lon <= 180.0)) n.item(0).fail("a longitude in [-180, 180] degrees");
  return {deg2rad(lat), deg2rad(lon)};
}

/// A ring in metres on a plane tangent at its first vertex (equirectangular; the footprint
/// checks need shape, not survey accuracy). Longitudes are unwrapped across the antimeridian.
std::vector<Eigen::Vector2d> roughPlane(const std::vector<std::pair<double, double>>& ring) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(ring.size());
  const double lat0 = ring.front().first, lon0 = ring.front().second;
  const double cos_lat0 = std::cos(lat0);
  for (const auto& [lat, lon] : ring) {
    const double dlon = wrapLongitudeDelta_rad(lon - lon0);
    out.emplace_back(dlon * cos_lat0 * kMeanEarthRadius_m, (lat - lat0) * kMeanEarthRadius_m);
  }
  return out;
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Do closed segments pq and rs share a point? (orientation tests, collinear overlap included)
bool segmentsTouch(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r, const Eigen::Vector2d& s) {
  const double d1 = cross2(q - p, r - p), d2 = cross2(q - p, s - p);
  const double d3 = cross2(s - r, p - r), d4 = cross2(s - r, q - r);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  const auto onSegment = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
           c.y() <= std::max(a.y(), b.y());
  };
  return (d1 == 0 && onSegment(p, q, r)) || (d2 == 0 && onSegment(p, q, s)) || (d3 == 0 && onSegment(r, s, p)) ||
         (d4 == 0 && onSegment(r, s, q));
}

/// The outer ring of a GeoJSON Polygon's coordinates, open and without repeated vertices,
/// checked: ≥ 3 vertices, a non-zero area, simple.
std::vector<std::pair<double, double>> outerRing(const Node& coordinates, bool& holes) {
  const json& rings = coordinates.array();
  if (rings.empty()) coordinates.fail("a list of linear rings");
  holes = rings.size() > 1;
  const Node outer = coordinates.item(0);
  const json& pts = outer.array();
  std::vector<std::pair<double, double>> ring;
  ring.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto p = position(outer.item(i));
    if (ring.empty() || p != ring.back()) ring.push_back(p);
  }
  if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
  if (ring.size() < 3) outer.fail("a linear ring with at least 3 distinct vertices");
  const std::vector<Eigen::Vector2d> xy = roughPlane(ring);
  if (!(std::abs(signedArea2(xy)) / 2.0 >= kMinFootprintArea_m2)) outer.fail("a footprint with an area (not degenerate)");
  const std::size_t n = xy.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = i + 1; k < n; ++k) {
      const bool adjacent = k == i + 1 || (i == 0 && k == n - 1);
      if (adjacent) {
        // Neighbours share a vertex; they must not fold back over each other.
        const std::size_t shared = k == i + 1 ? k : i;
        const Eigen::Vector2d& a = xy[k == i + 1 ? i : k];
        const Eigen::Vector2d& b = xy[shared];
        const Eigen::Vector2d& c = xy[(shared + 1) % n];
        if (cross2(b - a, c - b) == 0.0 && (b - a).dot(c - b) < 0.0) {
          outer.item(shared).fail("a simple ring (the edges at this vertex fold back over each other)");
        }
        continue;
      }
      if (segmentsTouch(xy[i], xy[(i + 1) % n], xy[k], xy[(k + 1) % n])) {
        outer.fail("a simple ring (edges " + std::to_string(i) + " and " + std::to_string(k) + " cross or touch)");
      }
    }
  }
  return ring;
}

/// The circumscribed kObstacleSides-gon of a circle of `radius_m` around a point.
std::vector<std::pair<double, double>> obstacleRing(const std::pair<double, double>& centre, double radius_m) {
  const PlaneFrame plane(centre.first, centre.second);
  const double r_vertex = radius_m / std::cos(M_PI / kObstacleSides);  // circumscribed: apothem = radius
  std::vector<std::pair<double, double>> ring;
  for (int k = 0; k < kObstacleSides; ++k) {
    const double a = 2.0 * M_PI * k / kObstacleSides;  // counter-clockwise from east
    const Eigen::Vector2d ll = plane.toLatLon({r_vertex * std::cos(a), r_vertex * std::sin(a)});
    ring.emplace_back(ll.x(), ll.y());
  }
  return ring;
}

/// Heights relative to the ground, as the properties give them.
struct HeightSpec {
  double height_m = 0.0;               ///< above the highest ground (unless top_amsl_m)
  double min_height_m = 0.0;           ///< above the lowest ground
  std::optional<double> top_amsl_m;    ///< absolute top
};

HeightSpec heights(const Node& props, const Node& feature, const BuildingOptions& options) {
  HeightSpec h;
  const double mpl = options.metres_per_level;
  if (props.has("min_height")) {
    h.min_height_m = heightValue(props.at("min_height"));
  } else {
    for (const char* key : {"building:min_level", "min_level"}) {
      if (props.has(key)) {
        h.min_height_m = levelsValue(props.at(key)) * mpl;
        break;
      }
    }
  }
  if (props.has("top_amsl_m")) {
    const Node t = props.at("top_amsl_m");
    const double v = t.number();
    if (!(std::abs(v) <= 10000.0)) t.fail("an altitude above mean sea level in [-10000, 10000] m");
    h.top_amsl_m = v;
    return h;
  }
  if (props.has("height")) {
    h.height_m = heightValue(props.at("height"));
  } else if (props.has("building:levels") || props.has("levels")) {
    const char* key = props.has("building:levels") ? "building:levels" : "levels";
    h.height_m = levelsValue(props.at(key)) * mpl;
  } else if (options.default_height_m) {
    h.height_m = *options.default_height_m;
  } else {
    throw ParseError(feature.source, 0, props.path + ".height", "",
                     "a height: 'height' (metres or \"40 ft\"), 'building:levels' / 'levels', or 'top_amsl_m'");
  }
  if (!(h.height_m > h.min_height_m)) {
    throw ParseError(feature.source, 0, props.path + ".height", std::to_string(h.height_m) + " m",
                     "a height above min_height (" + std::to_string(h.min_height_m) + " m)");
  }
  return h;
}

/// Base and top ellipsoidal heights of a footprint on the terrain (the safe convention in
/// buildings.hpp).
void placeOnTerrain(Building& b, const HeightSpec& h, const Terrain& terrain, const std::string& geometry_path,
                    const std::string& props_path) {
  const auto ground = terrain.rangeAmsl_m(b.ring_lat_lon_rad);
  if (!ground) {
    throw ParseError(b.source, 0, geometry_path, "a footprint outside the terrain raster or on a void",
                     "a footprint where the terrain model has heights (" + terrain.describe() + ")");
  }
  // The box for the geoid: latitudes, and longitudes unwrapped from the first vertex.
  double lat_min = b.ring_lat_lon_rad.front().first, lat_max = lat_min;
  const double lon0 = b.ring_lat_lon_rad.front().second;
  double west = lon0, east = lon0;
  for (const auto& [lat, lon] : b.ring_lat_lon_rad) {
    lat_min = std::min(lat_min, lat);
    lat_max = std::max(lat_max, lat);
    const double u = continuousLongitude_rad(lon, lon0);
    west = std::min(west, u);
    east = std::max(east, u);
  }
  const auto [n_min, n_max] = Geoid::egm96().undulationRange_m(lat_min, lat_max, west, east);
  b.base_h_ell_m = ground->first + n_min + h.min_height_m;
  b.top_h_ell_m = h.top_amsl_m ? *h.top_amsl_m + n_max : ground->second + n_max + h.height_m;
  if (!(b.top_h_ell_m > b.base_h_ell_m)) {  // only a top_amsl_m can end below the base
    throw ParseError(b.source, 0, props_path + ".top_amsl_m", std::to_string(h.top_amsl_m.value_or(NAN)),
                     "a top above the ground and min_height under the footprint (base " +
                         std::to_string(b.base_h_ell_m - n_min) + " m AMSL)");
  }
}

std::string featureLabel(const Node& feature, const Node& props) {
  std::string id;
  if (feature.has("id")) {
    id = feature.j.at("id").is_string() ? feature.j.at("id").get<std::string>() : feature.j.at("id").dump();
  } else if (props.has("@id") && props.j.at("@id").is_string()) {
    id = props.j.at("@id").get<std::string>();
  } else if (props.has("id")) {
    id = props.j.at("id").is_string() ? props.j.at("id").get<std::string>() : props.j.at("id").dump();
  }
  if (id.size() > kJsonQuoteChars) id = id.substr(0, kJsonQuoteChars) + "…";
  return id.empty() ? feature.path : feature.path + "(" + id + ")";
}

void parseFeature(const Node& feature0, const Terrain& terrain, const BuildingOptions& options,
                  std::vector<Building>& out) {
  if (!feature0.j.is_object()) feature0.fail("a GeoJSON Feature object");
  const json empty = json::object();
  const Node props0 = feature0.has("properties") ? feature0.at("properties")
                                                 : Node{empty, feature0.path + ".properties", feature0.source};
  if (!props0.j.is_object()) props0.fail("an object");
  const std::string label = featureLabel(feature0, props0);
  const Node feature{feature0.j, label, feature0.source};
  const Node props{props0.j, label + ".properties", feature0.source};
  const HeightSpec h = heights(props, feature, options);
  const Node geometry = feature.at("geometry");
  const Node type_node = geometry.at("type");
  const std::string type = type_node.str();

  const auto add = [&](std::vector<std::pair<double, double>> ring, bool holes, bool point, const std::string& part) {
    Building b;
    b.source = feature.source;
    b.feature = label + part;
    b.ring_lat_lon_rad = std::move(ring);
    b.holes_filled = holes;
    b.from_point = point;
    placeOnTerrain(b, h, terrain, label + (part.empty() ? ".geometry" : part), props.path);
    out.push_back(std::move(b));
  };
  if (type == "Polygon") {
    bool holes = false;
    auto ring = outerRing(geometry.at("coordinates"), holes);
    add(std::move(ring), holes, false, "");
  } else if (type == "MultiPolygon") {
    const Node polys = geometry.at("coordinates");
    if (polys.array().empty()) polys.fail("a list of polygons");
    for (std::size_t i = 0; i < polys.array().size(); ++i) {
      bool holes = false;
      auto ring = outerRing(polys.item(i), holes);
      add(std::move(ring), holes, false, ".geometry.coordinates[" + std::to_string(i) + "]");
    }
  } else if (type == "Point") {
    const auto centre = position(geometry.at("coordinates"));
    double radius_m = options.default_obstacle_radius_m;
    if (props.has("radius")) {
      const Node r = props.at("radius");
      radius_m = r.number();
      if (!(radius_m > 0.0 && radius_m <= 1000.0)) r.fail("a radius in (0, 1000] m");
    }
    if (std::abs(centre.first) > deg2rad(89.9)) geometry.at("coordinates").item(1).fail("a latitude within 89.9 degrees of the equator");
    add(obstacleRing(centre, radius_m), false, true, "");
  } else {
    type_node.fail("Polygon, MultiPolygon or Point");
  }
}

}  // namespace

std::optional<double> parseHeightText_m(const std::string& text) {
  const char* s = text.c_str();
  char* end = nullptr;
  while (std::isspace(static_cast<unsigned char>(*s))) ++s;
  if (*s == '\0') return std::nullopt;
  const double v = std::strtod(s, &end);
  if (end == s || !std::isfinite(v)) return std::nullopt;
  std::string unit(end);
  unit.erase(std::remove_if(unit.begin(), unit.end(), [](unsigned char c) { return std::isspace(c); }), unit.end());
  std::transform(unit.begin(), unit.end(), unit.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (unit.empty() || unit == "m" || unit == "metre" || unit == "metres" || unit == "meter" || unit == "meters") return v;
  if (unit == "ft" || unit == "'" || unit == "feet" || unit == "foot") return v * kMetresPerFoot;
  return std::nullopt;
}

std::vector<Building> parseBuildings(const json& doc, const std::string& source, const Terrain& terrain,
                                     const BuildingOptions& options) {
  if (!(options.metres_per_level > 0.0 && options.metres_per_level < 100.0) ||
      !(options.default_obstacle_radius_m > 0.0) ||
      (options.default_height_m && !(*options.default_height_m > 0.0 && *options.default_height_m <= kMaxHeight_m))) {
    throw std::invalid_argument("parseBuildings: metres per level in (0, 100), a positive obstacle radius and a default height in (0, 2000] m");
  }
  std::vector<Building> out;
  if (doc.is_object() && doc.contains("type") && doc.at("type") == "Feature") {
    parseFeature(Node{doc, "feature", source}, terrain, options, out);
    return out;
  }
  const Node root{doc, "", source};
  if (!doc.is_object() || !doc.contains("features")) {
    throw ParseError(source, 0, "features", doc.is_object() ? "" : quoteJson(doc), "a GeoJSON FeatureCollection of buildings");
  }
  const Node list{doc.at("features"), "features", source};
  for (std::size_t i = 0; i < list.array().size(); ++i) parseFeature(list.item(i), terrain, options, out);
  return out;
}

std::vector<Building> loadBuildings(const std::string& path, const Terrain& terrain, const BuildingOptions& options) {
  return parseBuildings(readJsonFile(path), path, terrain, options);
}

// --- prisms and meshes ------------------------------------------------------------------

double signedArea2(const std::vector<Eigen::Vector2d>& ring) {
  double a2 = 0.0;  // shoelace: Σ x_i·y_{i+1} − x_{i+1}·y_i
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) a2 += cross2(ring[i], ring[(i + 1) % n]);
  return a2;
}

Prism extrude(const Building& b, const LocalFrame& frame) {
  if (b.ring_lat_lon_rad.size() < 3) throw std::logic_error("extrude: " + b.feature + " has fewer than 3 vertices");
  Prism p;
  p.footprint_en.reserve(b.ring_lat_lon_rad.size());
  p.bottom_u_m = std::numeric_limits<double>::infinity();
  p.top_u_m = -std::numeric_limits<double>::infinity();
  for (const auto& [lat, lon] : b.ring_lat_lon_rad) {
    const Eigen::Vector3d base = frame.toEnu({lat, lon, b.base_h_ell_m});
    const Eigen::Vector3d top = frame.toEnu({lat, lon, b.top_h_ell_m});
    p.footprint_en.emplace_back(base.x(), base.y());
    p.bottom_u_m = std::min(p.bottom_u_m, base.z());
    p.top_u_m = std::max(p.top_u_m, top.z());
  }
  if (signedArea2(p.footprint_en) < 0.0) std::reverse(p.footprint_en.begin(), p.footprint_en.end());
  return p;
}

std::vector<std::array<int, 3>> earClip(const std::vector<Eigen::Vector2d>& ring) {
  const int n = static_cast<int>(ring.size());
  std::vector<std::array<int, 3>> tris;
  if (n < 3) return tris;
  tris.reserve(static_cast<std::size_t>(n - 2));
  std::vector<int> idx(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) idx[static_cast<std::size_t>(i)] = i;
  // Is vertex k of the remaining polygon an ear: convex, and no other remaining vertex inside
  // (or on) the triangle (prev, k, next)?
  const auto isEar = [&](std::size_t k) {
    const std::size_t m = idx.size();
    const Eigen::Vector2d& a = ring[static_cast<std::size_t>(idx[(k + m - 1) % m])];
    const Eigen::Vector2d& b = ring[static_cast<std::size_t>(idx[k])];
    const Eigen::Vector2d& c = ring[static_cast<std::size_t>(idx[(k + 1) % m])];
    if (!(cross2(b - a, c - b) > 0.0)) return false;  // reflex or collinear
    for (std::size_t q = 0; q < m; ++q) {
      if (q == k || q == (k + m - 1) % m || q == (k + 1) % m) continue;
      const Eigen::Vector2d& p = ring[static_cast<std::size_t>(idx[q])];
      if (p == a || p == b || p == c) continue;  // a repeated vertex is not "inside"
      if (cross2(b - a, p - a) >= 0.0 && cross2(c - b, p - b) >= 0.0 && cross2(a - c, p - c) >= 0.0) return false;
    }
    return true;
  };
  while (idx.size() > 3) {
    const std::size_t m = idx.size();
    std::size_t ear = m;
    for (std::size_t k = 0; k < m && ear == m; ++k) {
      if (isEar(k)) ear = k;
    }
    if (ear == m) {
      // No strict ear: only collinear or degenerate corners remain (or the ring is not
      // simple). Clip the least reflex corner so that the loop ends with n − 2 triangles.
      double best = -std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < m; ++k) {
        const Eigen::Vector2d& a = ring[static_cast<std::size_t>(idx[(k + m - 1) % m])];
        const Eigen::Vector2d& b = ring[static_cast<std::size_t>(idx[k])];
        const Eigen::Vector2d& c = ring[static_cast<std::size_t>(idx[(k + 1) % m])];
        const double turn = cross2(b - a, c - b);
        if (turn > best) {
          best = turn;
          ear = k;
        }
      }
    }
    tris.push_back({idx[(ear + m - 1) % m], idx[ear], idx[(ear + 1) % m]});
    idx.erase(idx.begin() + static_cast<long>(ear));
  }
  tris.push_back({idx[0], idx[1], idx[2]});
  return tris;
}

TriangleMesh prismMesh(const Prism& prism) {
  const int n = static_cast<int>(prism.footprint_en.size());
  if (n < 3) throw std::logic_error("prismMesh: a footprint needs at least 3 vertices, got " + std::to_string(n));
  std::vector<Eigen::Vector2d> ring = prism.footprint_en;
  const bool reversed = signedArea2(ring) < 0.0;  // make it counter-clockwise (extrude() already does)
  if (reversed) std::reverse(ring.begin(), ring.end());
  TriangleMesh mesh;
  mesh.vertices_enu.reserve(static_cast<std::size_t>(2 * n));
  for (const Eigen::Vector2d& p : ring) mesh.vertices_enu.emplace_back(p.x(), p.y(), prism.bottom_u_m);
  for (const Eigen::Vector2d& p : ring) mesh.vertices_enu.emplace_back(p.x(), p.y(), prism.top_u_m);
  mesh.triangles.reserve(static_cast<std::size_t>(4 * n - 4));
  for (const auto& t : earClip(ring)) {
    mesh.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});  // top cap: counter-clockwise from above, normal +U
    mesh.triangles.push_back({t[0], t[2], t[1]});              // bottom cap: reversed, normal −U
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    // Wall under footprint edge i → j; the footprint is counter-clockwise, so the outside is
    // on the edge's right and (b_j − b_i) × (t_j − b_i) points there.
    mesh.triangles.push_back({i, j, j + n});
    mesh.triangles.push_back({i, j + n, i + n});
  }
  return mesh;
}

}  // namespace skylane::maps
