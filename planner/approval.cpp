// The Approver and what it knows of the mission's area: the files loaded once, the ground, the
// validity of a planner state, sky masks, predicted protection levels and the integrity cost
// field. The approval itself (Impl::run and its steps) is in approval_steps.cpp.
#include "planner/approval.hpp"
#include "planner/approval_impl.hpp"

#include "geofence/obstruction_files.hpp"
#include "integrity/predict.hpp"
#include "maps/file_digest.hpp"
#include "maps/geoid.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/plane_frame.hpp"
#include "maps/sky_mask.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <string>

namespace skylane::planner {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A number as a person would write it: whole numbers without a fraction.
std::string numberText(double v) {
  if (std::floor(v) == v && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  return maps::quoteJson(nlohmann::json(v));
}

/// A computed height, to a decimetre.
std::string decimetres(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << v;
  return s.str();
}

/// φ(r) of the file comment: grows without bound as PL approaches the alert limit.
double integrityPenalty(double r) {
  if (!(r < 0.99)) return 1e4;
  const double q = r / (1.0 - r);
  return q * q;
}

}  // namespace

namespace {

/// Every zone and building file the mission names can be read; else the mission's field is named
/// with the path it resolved to.
void requireReadableInputs(const Mission& m) {
  auto check = [&m](const std::string& path, const std::string& field) {
    if (!std::ifstream(path)) throw maps::ParseError(m.source, 0, field, path, "a readable file (the path as resolved from the mission)");
  };
  for (std::size_t i = 0; i < m.zone_files.size(); ++i) {
    // The .plan's geoFence joins the zones without being listed (planner/mission.hpp).
    check(m.zone_files[i], m.zone_files[i] == m.qgc_plan_file ? "$.qgc_plan" : "$.zones[" + std::to_string(i) + "]");
  }
  if (!m.buildings_file.empty()) check(m.buildings_file, "$.buildings");
}

/// The orbit files' ages at the departure — at whichever end of the window is farther from each
/// file's epoch. Throws past an error limit; returns the warnings.
std::vector<std::string> checkOrbitAges(const integrity::OrbitSource& orbits, const Mission& m) {
  std::vector<integrity::OrbitFileAge> worst = orbits.fileAges(m.departure_earliest);
  const std::vector<integrity::OrbitFileAge> at_latest = orbits.fileAges(m.departure_latest);
  for (std::size_t i = 0; i < worst.size(); ++i) {
    if (at_latest[i].age_s > worst[i].age_s) worst[i] = at_latest[i];
  }
  std::vector<std::string> warnings;
  for (const integrity::OrbitFileAge& age : worst) {
    std::string w = integrity::requireUsableAge(age, "the departure");
    if (!w.empty()) warnings.push_back(std::move(w));
  }
  return warnings;
}

}  // namespace

MissionRecord missionRecord(const Mission& m) {
  MissionRecord r;
  r.name = m.name;
  r.source = m.source;
  if (!m.source.empty()) r.source_absolute = std::filesystem::absolute(m.source).lexically_normal().string();
  r.k1 = m.levels.k1;
  r.k2 = m.levels.k2;
  r.navigation = m.navigation;
  r.policy = m.policy;
  r.seed = m.seed;
  auto add = [&r](const std::string& role, const std::string& path) {
    if (!path.empty()) r.inputs.push_back({role, path, maps::fileSha256Hex(path)});
  };
  // A mission parsed from memory (a request, a test) names no file: nothing to digest.
  if (std::filesystem::is_regular_file(m.source)) add("mission", m.source);
  for (const std::string& f : m.zone_files) add("zones", f);
  add("buildings", m.buildings_file);
  add("terrain", m.terrain_file);
  for (const std::string& f : m.orbit_files) add("orbits", f);
  return r;
}

Approver::Impl::Impl(Mission mission)
    : m(std::move(mission)),
      frame(m.points.front().lat_rad, m.points.front().lon_rad),
      terrain(m.terrain_file.empty() ? maps::Terrain::flat(m.ground_amsl_m) : maps::Terrain::fromRaster(m.terrain_file)) {
  try {
    limits = geofence::alertLimits(m.vehicle, m.levels);
  } catch (const std::invalid_argument& e) {
    throw maps::ParseError(m.source, 0, "$.k1/$.k2/$.vehicle", "", e.what());
  }
  placeStops();
  requireReadableInputs(m);
  loadObstructions();
  orbits = integrity::loadOrbitFiles(m.orbit_files, m.source, "$.orbits");
  record = missionRecord(m);  // the files as they were read
  // Search box: every mission point ± margin; heights from the terrain's range over it.
  Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
  for (const MissionPoint& p : m.points) {
    const Eigen::Vector2d xy = frame.toPlane(p.lat_rad, p.lon_rad);
    lo = lo.cwiseMin(xy);
    hi = hi.cwiseMax(xy);
  }
  lo.array() -= m.margin_m;
  hi.array() += m.margin_m;
  double g_lo = kInf, g_hi = -kInf;
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 20; ++j) {
      const auto g = ground(Eigen::Vector2d(lo.x() + (hi.x() - lo.x()) * i / 20.0, lo.y() + (hi.y() - lo.y()) * j / 20.0));
      if (!g) continue;
      g_lo = std::min(g_lo, *g);
      g_hi = std::max(g_hi, *g);
    }
  }
  if (!std::isfinite(g_lo)) throw maps::ParseError(m.source, 0, "$.terrain", m.terrain_file, "terrain covering the mission area");
  lower << lo, g_lo + m.min_agl_m - 1.0;
  upper << hi, g_hi + m.max_agl_m + 1.0;
  ground_grid.emplace(frame, terrain, lo, hi);
}

std::optional<double> Approver::Impl::ground(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d ll = frame.toLatLon(xy);
  return terrain.heightEllipsoid_m(ll.x(), ll.y());
}

maps::Geodetic Approver::Impl::geodetic(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d ll = frame.toLatLon(p.head<2>());
  return {ll.x(), ll.y(), p.z()};
}

bool Approver::Impl::valid(const Eigen::Vector3d& p, const maps::GpsTime& t0, const maps::GpsTime& t1,
                           const std::vector<approval_steps::Penalty>& penalties) const {
  // The state's (lat, lon) from the map-frame grid (within its bound), for the ground and the geoid.
  const Eigen::Vector2d ll = ground_grid ? ground_grid->toLatLon(p.head<2>()) : frame.toLatLon(p.head<2>());
  const auto g = terrain.heightEllipsoid_m(ll.x(), ll.y());
  if (!g) return false;
  const double agl = p.z() - *g;
  if (agl < m.min_agl_m || agl > m.max_agl_m) return false;
  if (m.max_amsl_m && maps::Geoid::egm96().amslFromEllipsoidal_m(ll.x(), ll.y(), p.z()) > *m.max_amsl_m) {
    return false;
  }
  for (const auto& [c, r] : penalties) {
    if ((p - c).norm() < r) return false;
  }
  const geofence::TimedVolume v{t0, t1, planningVolume(p)};
  return !obstructions->conflicts(v);
}

maps::SkyMask Approver::Impl::skyMaskAt(const maps::Geodetic& g) const {
  const bool raster = !m.terrain_file.empty();
  maps::SkyMaskOptions options;
  options.floor_rad = maps::deg2rad(m.mask_deg);  // below the receiver's mask nothing matters
  return maps::computeSkyMask(g, index.get(), raster ? &terrain : nullptr, options);
}

bool Approver::Impl::masked() const { return index || !m.terrain_file.empty(); }

integrity::PredictSample Approver::Impl::predictAt(const maps::Geodetic& g, const maps::GpsTime& t,
                                                   const std::optional<maps::SkyMask>& mask) const {
  integrity::PredictRequest req;
  req.place = g;
  req.mask_rad = maps::deg2rad(m.mask_deg);
  req.model = m.model;
  req.sky_mask = mask;
  req.with_exclusion = m.with_exclusion;
  integrity::PredictSample s = integrity::predictAt(orbits, req, t, m.method);
  if (m.navigation.kind == NavigationKind::kReceiver) {
    // The receiver states its PLs: they hold wherever it is (the satellites are still counted).
    s.pl.pl_computed = true;
    s.pl.hpl_m = m.navigation.hpl_m;
    s.pl.vpl_m = m.navigation.vpl_m;
  }
  return s;
}

double Approver::Impl::ratioOf(const integrity::PredictSample& s) const {
  if (!s.pl.pl_computed) return kInf;
  return std::max(s.pl.hpl_m / limits.level2.hal_m, s.pl.vpl_m / limits.level2.val_m);
}

void Approver::Impl::buildCostGrid(const maps::GpsTime& t_mid) {
  CostGrid& field = cost_field;
  field.lower = lower.head<2>();
  field.cell_m = m.cost_cell_m;
  while ((upper.x() - lower.x()) * (upper.y() - lower.y()) / (field.cell_m * field.cell_m) > 20000.0) field.cell_m *= 1.5;
  const double cell_m = field.cell_m;
  const int cols = field.cols = std::max(1, static_cast<int>(std::ceil((upper.x() - lower.x()) / cell_m)));
  const int rows = field.rows = std::max(1, static_cast<int>(std::ceil((upper.y() - lower.y()) / cell_m)));
  const std::size_t n = static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
  std::vector<double>& cost = field.cost;
  cost.assign(m.cost_weight > 0.0 ? n : 0, 0.0);
  grid_pl.assign(n, Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  const bool with_masks = masked();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d xy(lower.x() + (c + 0.5) * cell_m, lower.y() + (r + 0.5) * cell_m);
      const auto g = ground(xy);
      if (!g) continue;
      const maps::Geodetic place = geodetic(Eigen::Vector3d(xy.x(), xy.y(), *g + m.cruise_agl_m));
      const integrity::PredictSample s =
          predictAt(place, t_mid, with_masks ? std::optional(skyMaskAt(place)) : std::nullopt);
      const std::size_t k = static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c);
      if (s.pl.pl_computed) grid_pl[k] = Eigen::Vector2d(s.pl.hpl_m, s.pl.vpl_m);
      if (!cost.empty()) cost[k] = m.cost_weight * integrityPenalty(ratioOf(s));
    }
  }
}

geofence::ProtectionVolume Approver::Impl::planningVolume(const Eigen::Vector3d& p) const {
  double h = limits.level1.hal_m, v = limits.level1.val_m;
  if (!grid_pl.empty()) {
    const Eigen::Vector2d& pl = grid_pl[cost_field.cellOf(p)];
    if (std::isfinite(pl.x())) {
      h = std::max(h, 1.2 * pl.x());
      v = std::max(v, 1.2 * pl.y());
    }
  }
  return {p, h, v};
}


void Approver::Impl::placeStops() {
  if (!m.point_flights.empty() && m.point_flights.size() != m.points.size()) {
    throw std::logic_error("Approver: " + std::to_string(m.point_flights.size()) + " point flights for " +
                           std::to_string(m.points.size()) + " mission points");
  }
  mission_stops.clear();
  mission_timing.clear();
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const Eigen::Vector2d xy = frame.toPlane(m.points[i].lat_rad, m.points[i].lon_rad);
    const auto g = ground(xy);
    if (!g) {
      throw maps::ParseError(m.source, 0, m.qgc_plan_file.empty() ? "$.start/$.waypoints/$.goal" : "$.qgc_plan", "",
                             "route points the terrain model covers");
    }
    const Eigen::Vector3d p(xy.x(), xy.y(), stopHeight(i, *g));
    checkStopHeight(i, p, *g);
    mission_stops.push_back(p);
    approval_steps::StopTiming st{m.cruise_speed_mps, 0.0};
    if (!m.point_flights.empty()) {
      st.speed_mps = m.point_flights[i].speed_mps.value_or(m.cruise_speed_mps);
      st.hover_s = m.point_flights[i].hover_s;
    }
    mission_timing.push_back(st);
  }
}

double Approver::Impl::stopHeight(std::size_t i, double ground_m) const {
  if (m.point_flights.empty() || !m.point_flights[i].height) return ground_m + m.cruise_agl_m;
  const PointHeight& h = *m.point_flights[i].height;
  switch (h.reference) {
    case HeightReference::kAboveGround: return ground_m + h.value_m;
    case HeightReference::kAmsl:
      return maps::Geoid::egm96().ellipsoidalFromAmsl_m(m.points[i].lat_rad, m.points[i].lon_rad, h.value_m);
    case HeightReference::kAboveHome: break;
  }
  // Relative to home: above the ground at the home, where the autopilot's altitude is zeroed.
  const MissionPoint home = m.qgc_home.value_or(m.points.front());
  const auto home_ground = ground(frame.toPlane(home.lat_rad, home.lon_rad));
  if (!home_ground) {
    throw maps::ParseError(m.qgc_plan_file, 0, "$.mission.plannedHomePosition", "",
                           "a home the terrain model covers (heights relative to home, e.g. " + h.field + ", need it)");
  }
  return *home_ground + h.value_m;
}

void Approver::Impl::checkStopHeight(std::size_t i, const Eigen::Vector3d& p, double ground_m) const {
  if (m.point_flights.empty() || !m.point_flights[i].height) return;  // cruise AGL: checked with the mission
  const PointHeight& h = *m.point_flights[i].height;
  const double agl = p.z() - ground_m;
  std::string broken;
  if (agl < m.min_agl_m) broken = "below altitude.min_agl_m " + numberText(m.min_agl_m) + " m";
  if (agl > m.max_agl_m) broken = "above altitude.max_agl_m " + numberText(m.max_agl_m) + " m";
  std::string here = decimetres(agl) + " m above the ground";
  if (m.max_amsl_m) {
    const double amsl = maps::Geoid::egm96().amslFromEllipsoidal_m(m.points[i].lat_rad, m.points[i].lon_rad, p.z());
    if (broken.empty() && amsl > *m.max_amsl_m) {
      broken = "above altitude.max_amsl_m " + numberText(*m.max_amsl_m) + " m";
      here = decimetres(amsl) + " m above mean sea level";
    }
  }
  if (broken.empty()) return;
  throw maps::ParseError(m.qgc_plan_file, 0, h.field, numberText(h.value_m),
                         "a height within the mission's altitude limits (this one is " + here + " there, " + broken +
                             ")");
}

std::vector<RoutePoint> Approver::Impl::timeRoute(const std::vector<Eigen::Vector3d>& pts,
                                                  const std::vector<approval_steps::StopTiming>& per_point) const {
  if (per_point.size() != pts.size()) throw std::logic_error("timeRoute: one timing per point expected");
  std::vector<RoutePoint> out;
  double t = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i > 0) {
      const Eigen::Vector3d d = pts[i] - pts[i - 1];
      t += out.back().hover_s;
      t += std::max(d.head<2>().norm() / per_point[i].speed_mps, std::abs(d.z()) / m.climb_speed_mps);
    }
    RoutePoint rp;
    rp.xyz = pts[i];
    const maps::Geodetic g = geodetic(pts[i]);
    rp.lat_rad = g.lat_rad;
    rp.lon_rad = g.lon_rad;
    rp.h_ell_m = g.h_ell_m;
    rp.alt_amsl_m = maps::Geoid::egm96().amslFromEllipsoidal_m(g.lat_rad, g.lon_rad, g.h_ell_m);
    rp.eta_s = t;
    rp.hover_s = per_point[i].hover_s;
    out.push_back(rp);
  }
  return out;
}

Eigen::Vector3d positionAlong(const std::vector<RoutePoint>& route, double t_s) {
  if (route.empty()) throw std::invalid_argument("positionAlong: an empty route");
  if (t_s <= route.front().eta_s + route.front().hover_s) return route.front().xyz;
  for (std::size_t i = 1; i < route.size(); ++i) {
    if (t_s <= route[i].eta_s) {
      const double leaves_s = route[i - 1].eta_s + route[i - 1].hover_s;
      const double span = route[i].eta_s - leaves_s;
      const double f = span > 0 ? std::max(0.0, t_s - leaves_s) / span : 1.0;
      return route[i - 1].xyz + f * (route[i].xyz - route[i - 1].xyz);
    }
    if (t_s <= route[i].eta_s + route[i].hover_s) return route[i].xyz;  // hovering there
  }
  return route.back().xyz;
}

void Approver::Impl::loadObstructions() {
  const auto format = airspace::parseZoneFormat(m.zone_format);
  if (!format) throw maps::ParseError(m.source, 0, "$.zone_format", m.zone_format, "auto, ed269, ed318, geojson or qgc");
  geofence::ZonePolicy policy;
  policy.authorisations = m.authorisations;
  geofence::FenceOptions options;
  options.horizon_m = 500.0;  // zones within 500 m are reported with their clearance
  std::set<std::string> qgc_plans;  // the .plan's geoFence: QGroundControl whatever zone_format says
  if (!m.qgc_plan_file.empty()) qgc_plans.insert(m.qgc_plan_file);
  auto loaded = std::make_unique<geofence::Obstructions>(geofence::loadObstructions(
      {m.zone_files, *format, m.buildings_file}, frame, terrain, policy, options, qgc_plans));
  std::unique_ptr<maps::BuildingIndex> built;
  if (!loaded->buildings().empty()) {
    const maps::Geodetic origin{m.points.front().lat_rad, m.points.front().lon_rad, 0.0};
    built = std::make_unique<maps::BuildingIndex>(loaded->buildings(), origin);
  }
  obstructions = std::move(loaded);  // only once both are read: a bad file leaves the old ones
  index = std::move(built);
}

Approver::Approver(Mission mission) : impl_(std::make_unique<Impl>(std::move(mission))) {}

void Approver::reloadZones() {
  impl_->loadObstructions();
  impl_->record = missionRecord(impl_->m);
}
Approver::~Approver() = default;
const Mission& Approver::mission() const { return impl_->m; }
const maps::PlaneFrame& Approver::frame() const { return impl_->frame; }
const maps::PlaneGrid& Approver::fixProjection() const { return impl_->fix_projection; }
const geofence::Obstructions& Approver::obstructions() const { return *impl_->obstructions; }
const integrity::OrbitSource& Approver::orbits() const { return impl_->orbits; }

std::vector<Eigen::Vector3d> Approver::missionStops() const { return impl_->mission_stops; }

std::optional<double> Approver::groundHeight(const Eigen::Vector2d& xy_map) const { return impl_->ground(xy_map); }

ApprovalReport Approver::approve(const std::function<void(const std::string&)>& progress) {
  const Mission& m = impl_->m;
  std::vector<maps::GpsTime> departures;
  for (double dt = 0.0; dt <= (m.departure_latest - m.departure_earliest) + 1e-6; dt += m.departure_step_s) {
    departures.push_back(m.departure_earliest.plus(dt));
  }
  std::vector<std::string> warnings = checkOrbitAges(impl_->orbits, m);
  ApprovalReport report = impl_->run(impl_->mission_stops, impl_->mission_timing, departures, false, progress);
  report.warnings.insert(report.warnings.begin(), warnings.begin(), warnings.end());
  return report;
}

ApprovalReport Approver::replanFrom(const Eigen::Vector3d& p_map, const maps::GpsTime& now, std::size_t next_stop,
                                    const std::function<void(const std::string&)>& progress) {
  if (!p_map.allFinite()) throw std::invalid_argument("replanFrom: the vehicle's position is not finite");
  std::vector<Eigen::Vector3d> all = missionStops();
  if (next_stop < 1 || next_stop >= all.size()) {
    throw std::invalid_argument("replanFrom: next stop " + std::to_string(next_stop) + " is not one of the mission's 1.." +
                                std::to_string(all.size() - 1));
  }
  std::vector<Eigen::Vector3d> stops{p_map};
  stops.insert(stops.end(), all.begin() + static_cast<std::ptrdiff_t>(next_stop), all.end());
  // From the vehicle: no hover where it is now (one under way there is over when it replans).
  std::vector<approval_steps::StopTiming> timing{{impl_->m.cruise_speed_mps, 0.0}};
  timing.insert(timing.end(), impl_->mission_timing.begin() + static_cast<std::ptrdiff_t>(next_stop),
                impl_->mission_timing.end());
  return impl_->run(stops, timing, {now}, true, progress);
}

}  // namespace skylane::planner
