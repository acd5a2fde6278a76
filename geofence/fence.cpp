#include "geofence/fence.hpp"

#include "geofence/zone_heights.hpp"

#include "airspace/applicability.hpp"
#include "maps/geodesy.hpp"

#include <algorithm>
#include <iterator>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace skylane::geofence {
namespace {

/// The least radius of curvature of the WGS-84 ellipsoid: the meridian radius at the equator,
/// a(1 − e²) [m]. Scale bounds use it so that they hold everywhere on the ellipsoid.
constexpr double kLeastRadiusOfCurvature_m = 6378137.0 * (1.0 - 0.00669437999014);

/// The worse of two verdicts: outside over indeterminate over inside.
int severity(Verdict v) { return v == Verdict::kOutside ? 2 : (v == Verdict::kIndeterminate ? 1 : 0); }

/// std::stable_sort's order (equal elements keep theirs) over [first, last), by insertion for a
/// few checks (a check usually reports a handful of zones, and std::stable_sort allocates a
/// buffer for every call).
template <class Iterator, class Less>
void stableSortByInsertion(Iterator first, Iterator last, Less less) {
  constexpr std::ptrdiff_t kInsertionMax = 32;
  if (last - first > kInsertionMax) {
    std::stable_sort(first, last, less);
    return;
  }
  for (Iterator i = first; i != last; ++i) std::rotate(std::upper_bound(first, i, *i, less), i, std::next(i));
}

Check boxCheck(Level level, const Containment& c) {
  Check out;
  out.level = level;
  out.verdict = c.verdict;
  out.index = c.segment;
  out.subject = "segment " + std::to_string(c.segment);
  out.margin_h_m = c.margin_h_m;
  out.margin_v_m = c.margin_v_m;
  out.across_joint = c.across_joint;
  return out;
}

/// Appends the convex pieces of a ring given in latitude/longitude [rad] (either winding), each
/// with the template's heights, to `out`.
template <class LatLonRange, class ToPlane>
void appendRingPieces(const LatLonRange& ring_ll, ToPlane toPlane, const airspace::PlanarPrism& heights, PieceOwner owner,
                      std::size_t owner_index, std::vector<ScenePiece>& out) {
  airspace::PlanarRing ring;
  ring.reserve(ring_ll.size());
  for (const auto& p : ring_ll) ring.push_back(toPlane(p));
  if (airspace::twiceSignedArea_m2(ring) < 0) std::reverse(ring.begin(), ring.end());
  for (airspace::PlanarRing& piece : airspace::convexPieces(ring)) {
    airspace::PlanarPrism q = heights;
    q.ring = std::move(piece);
    out.push_back({std::move(q), owner, owner_index});
  }
}

}  // namespace

const char* levelName(Level l) {
  switch (l) {
    case Level::kCorridor: return "level1";
    case Level::kAirspace: return "level2";
    case Level::kZone: return "zone";
    case Level::kObstacle: return "obstacle";
    case Level::kKeepIn: return "keep_in";
  }
  return "?";
}

const char* verdictWord(Level l, Verdict v) {
  if (isContainmentLevel(l) || v == Verdict::kIndeterminate) return verdictName(v);
  return v == Verdict::kInside ? "clear" : "met";
}

bool counts(const airspace::Zone& zone, const ZonePolicy& policy) {
  if (zone.keep_in) return false;  // not to stay clear of: the keep-in check holds it
  const bool authorised = policy.authorisations.count(zone.identifier) > 0;
  switch (zone.restriction) {
    case airspace::Restriction::kProhibited: return true;
    case airspace::Restriction::kReqAuthorisation: return !authorised;
    case airspace::Restriction::kConditional: return policy.count_conditional && !authorised;
    case airspace::Restriction::kNoRestriction: return policy.count_no_restriction;
  }
  return true;
}

std::vector<ScenePiece> zonePieces(const std::vector<airspace::Zone>& zones, const maps::PlaneFrame& frame,
                                   const airspace::VerticalModel& model) {
  std::vector<ScenePiece> pieces;
  const Eigen::Vector2d origin_ll = frame.toLatLon(Eigen::Vector2d::Zero());
  for (std::size_t zi = 0; zi < zones.size(); ++zi) {
    const airspace::Zone& z = zones[zi];
    if (z.keep_in) continue;
    for (std::size_t vi = 0; vi < z.volumes.size(); ++vi) {
      const airspace::Volume& v = z.volumes[vi];
      const VolumeHeights heights = volumeHeights(z, vi, model);
      airspace::PlanarPrism prism;
      prism.floor_h_ell_m = heights.floor.h_ell_min_m;
      prism.ceiling_h_ell_m = heights.ceiling.h_ell_max_m;
      if (v.outline.kind == airspace::Outline::Kind::kCircle) {
        const airspace::LatLon& c = v.outline.centre;
        // Azimuthal scale k' = c / sin c of the azimuthal equidistant projection, c = ρ/R the
        // angular distance from the centre (Snyder, "Map Projections — A Working Manual", USGS
        // PP 1395, 1987, §25, sphere); the radial scale is 1. Taken at the circle's farthest
        // point from the origin, it bounds the stretch of every radius of the circle.
        const double rho_m = maps::geodesicDistance_m(origin_ll.x(), origin_ll.y(), c.lat_rad, c.lon_rad) +
                             v.outline.radius_m;
        const double x = std::min(rho_m / kLeastRadiusOfCurvature_m, 3.0);
        const double k = x > 0 ? x / std::sin(x) : 1.0;
        prism.centre = frame.toPlane(c.lat_rad, c.lon_rad);
        prism.radius_m = v.outline.radius_m * k + kCircleRounding_m;
        pieces.push_back({prism, PieceOwner::kZone, zi});
        continue;
      }
      appendRingPieces(v.outline.ring, [&](const airspace::LatLon& p) { return frame.toPlane(p.lat_rad, p.lon_rad); },
                       prism, PieceOwner::kZone, zi, pieces);
    }
  }
  return pieces;
}

std::vector<ScenePiece> obstaclePieces(const std::vector<maps::Building>& buildings, const maps::PlaneFrame& frame) {
  std::vector<ScenePiece> pieces;
  for (std::size_t bi = 0; bi < buildings.size(); ++bi) {
    const maps::Building& b = buildings[bi];
    airspace::PlanarPrism heights;
    heights.floor_h_ell_m = b.base_h_ell_m;
    heights.ceiling_h_ell_m = b.top_h_ell_m;
    appendRingPieces(b.ring_lat_lon_rad, [&](const std::pair<double, double>& p) { return frame.toPlane(p.first, p.second); },
                     heights, PieceOwner::kObstacle, bi, pieces);
  }
  return pieces;
}

Obstructions::Obstructions(std::vector<airspace::Zone> zones, std::vector<maps::Building> buildings, Scene scene,
                           ZonePolicy policy, FenceOptions options, std::vector<KeepInVolume> keep_in)
    : zones_(std::move(zones)),
      buildings_(std::move(buildings)),
      keep_in_(std::move(keep_in)),
      scene_(std::move(scene)),
      policy_(std::move(policy)),
      options_(options) {
  if (!(std::isfinite(options_.tolerance_m) && options_.tolerance_m >= 0)) {
    throw std::invalid_argument("fence tolerance must be a finite number of metres ≥ 0");
  }
  if (!(std::isfinite(options_.horizon_m) && options_.horizon_m >= 0)) {
    throw std::invalid_argument("fence clearance horizon must be a finite number of metres ≥ 0");
  }
  for (const ScenePiece& p : scene_.pieces()) {
    const std::size_t n = p.owner == PieceOwner::kZone ? zones_.size() : buildings_.size();
    if (p.owner_index >= n) {
      throw std::invalid_argument(std::string("scene piece names ") + (p.owner == PieceOwner::kZone ? "zone " : "obstacle ") +
                                  std::to_string(p.owner_index) + " but there are only " + std::to_string(n));
    }
  }
  for (const KeepInVolume& k : keep_in_) {
    if (k.zone >= zones_.size() || !zones_[k.zone].keep_in) {
      throw std::invalid_argument("keep-in volume names zone " + std::to_string(k.zone) + ", which is not a keep-in zone of " +
                                  std::to_string(zones_.size()));
    }
  }
  zone_counts_.reserve(zones_.size());
  always_active_.reserve(zones_.size());
  for (const airspace::Zone& z : zones_) {
    zone_counts_.push_back(counts(z, policy_));
    always_active_.push_back(airspace::isAlwaysActive(z));
  }
  for (const ScenePiece& p : scene_.pieces()) {
    pieces_in_band_ = pieces_in_band_ && p.prism.floor_h_ell_m >= kSceneFloor_h_ell_m &&
                      p.prism.ceiling_h_ell_m <= kSceneCeiling_h_ell_m;
  }
}

bool Obstructions::takes(PieceOwner owner, std::size_t i, const TimedVolume& v) const {
  // Zones count when the policy says so and they are active in the interval; obstacles always.
  return owner == PieceOwner::kObstacle ||
         (zone_counts_[i] && (always_active_[i] || airspace::isActiveDuring(zones_[i], v.t0, v.t1)));
}

std::optional<ProtectionVolume> Obstructions::sceneVolume(const ProtectionVolume& given) const {
  // A volume taller than the scene's height band (a VPL of kilometres from a poor geometry) is
  // cut to the band when every piece lies inside it (unlimited limits are cut to the band; a
  // finite one above 20 km is not): the cut volume then meets exactly the pieces the whole one
  // meets, and its vertical margins are those of the cut volume. Otherwise Scene::query refuses it.
  ProtectionVolume volume = given;
  requireValid(volume);
  const double lo = std::max(volume.p_map.z() - volume.vpl_m, kSceneFloor_h_ell_m);
  const double hi = std::min(volume.p_map.z() + volume.vpl_m, kSceneCeiling_h_ell_m);
  if (pieces_in_band_ && (lo > volume.p_map.z() - volume.vpl_m || hi < volume.p_map.z() + volume.vpl_m)) {
    if (!(hi > lo)) return std::nullopt;  // wholly above or below every zone and obstacle
    volume.p_map.z() = 0.5 * (lo + hi);
    volume.vpl_m = 0.5 * (hi - lo);
  }
  return volume;
}

Check Obstructions::hitCheck(const SceneHit& h) const {
  const Separation& s = h.separation;
  Check c;
  c.level = h.owner == PieceOwner::kZone ? Level::kZone : Level::kObstacle;
  c.index = h.owner_index;
  if (c.level == Level::kZone) {
    const airspace::Zone& z = zones_[h.owner_index];
    c.subject = z.identifier;
    c.name = z.name;
    c.restriction = airspace::restrictionLabel(z);
  } else {
    c.subject = buildings_[h.owner_index].feature;
  }
  c.margin_h_m = s.margin_h_m;
  c.margin_v_m = s.margin_v_m;
  c.clearance_m = s.clearance_m;
  c.exact = s.exact;
  // The narrow phase has the last word on meeting; the margin says how close it is.
  const double deciding_m = std::max(s.margin_h_m, s.margin_v_m);
  c.verdict = s.meets ? (deciding_m >= -options_.tolerance_m ? Verdict::kIndeterminate : Verdict::kOutside)
                      : (deciding_m <= options_.tolerance_m ? Verdict::kIndeterminate : Verdict::kInside);
  return c;
}

void Obstructions::appendChecks(const TimedVolume& v, double horizon_m, std::vector<Check>& out) const {
  const std::optional<ProtectionVolume> volume = sceneVolume(v.volume);
  if (!volume) return;
  thread_local std::vector<SceneHit> hits;  // this thread's scratch: no allocation once grown
  scene_.query(*volume, horizon_m, [&](PieceOwner owner, std::size_t i) { return takes(owner, i, v); }, hits);
  // One check per zone or obstacle, from the piece that decides it.
  const std::size_t first = out.size();
  for (const SceneHit& h : hits) out.push_back(hitCheck(h));
  stableSortByInsertion(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), [](const Check& a, const Check& b) {
    if (a.level != b.level) return a.level < b.level;
    if (severity(a.verdict) != severity(b.verdict)) return severity(a.verdict) > severity(b.verdict);
    return *a.clearance_m < *b.clearance_m;
  });
}

std::vector<Check> Obstructions::check(const TimedVolume& v, double horizon_m) const {
  std::vector<Check> near;
  appendChecks(v, horizon_m, near);
  return near;
}

std::vector<Check> Obstructions::check(const TimedVolume& v) const { return check(v, options_.horizon_m); }

std::optional<KeepInMargins> Obstructions::keepInMarginsAt(const TimedVolume& v,
                                                           std::vector<const KeepInVolume*>& active) const {
  active.clear();
  for (const KeepInVolume& k : keep_in_) {
    if (airspace::isActiveDuring(zones_[k.zone], v.t0, v.t1)) active.push_back(&k);
  }
  if (active.empty()) return std::nullopt;
  requireValid(v.volume);
  return keepInMargins(v.volume, active);
}

Verdict Obstructions::keepInVerdict(const KeepInMargins& m) const {
  const double deciding_m = std::min(m.margin_h_m, m.margin_v_m);
  return deciding_m > options_.tolerance_m    ? Verdict::kInside
         : deciding_m < -options_.tolerance_m ? Verdict::kOutside
                                              : Verdict::kIndeterminate;
}

std::optional<Check> Obstructions::keepIn(const TimedVolume& v) const {
  thread_local std::vector<const KeepInVolume*> active;  // this thread's scratch
  const std::optional<KeepInMargins> m = keepInMarginsAt(v, active);
  if (!m) return std::nullopt;
  const airspace::Zone& z = zones_[active[m->nearest]->zone];
  Check c;
  c.level = Level::kKeepIn;
  c.index = active[m->nearest]->zone;
  c.subject = z.identifier;
  c.name = z.name;
  c.restriction = std::string(airspace::restrictionLabel(z));
  c.margin_h_m = m->margin_h_m;
  c.margin_v_m = m->margin_v_m;
  c.verdict = keepInVerdict(*m);
  return c;
}

std::optional<Check> Obstructions::firstConflict(const TimedVolume& v, bool with_keep_in) const {
  if (with_keep_in) {
    if (std::optional<Check> k = keepIn(v); k && k->verdict != Verdict::kInside) return k;
  }
  for (Check& c : check(v, 0.0)) {
    if (c.verdict != Verdict::kInside) return std::move(c);
  }
  return std::nullopt;
}

bool Obstructions::conflicts(const TimedVolume& v, bool with_keep_in) const {
  if (with_keep_in) {  // keepIn()'s verdict, without the check's names
    thread_local std::vector<const KeepInVolume*> active;
    const std::optional<KeepInMargins> m = keepInMarginsAt(v, active);
    if (m && keepInVerdict(*m) != Verdict::kInside) return true;
  }
  // Every zone or obstacle check(v, 0) reports is a conflict: met (outside or indeterminate),
  // or at clearance 0 with a deciding margin ≤ 0 (indeterminate).
  const std::optional<ProtectionVolume> volume = sceneVolume(v.volume);
  return volume && scene_.reachesAny(*volume, [&](PieceOwner owner, std::size_t i) { return takes(owner, i, v); });
}

Fence::Fence(Corridor level1, Corridor level2, std::vector<airspace::Zone> zones, std::vector<maps::Building> buildings,
             Scene scene, ZonePolicy policy, FenceOptions options)
    : Fence(std::move(level1), std::move(level2),
            Obstructions(std::move(zones), std::move(buildings), std::move(scene), std::move(policy), options)) {}

Fence::Fence(Corridor level1, Corridor level2, Obstructions obstructions)
    : level1_(std::move(level1)), level2_(std::move(level2)), obstructions_(std::move(obstructions)) {}

FenceVerdict checkVolume(const Corridor& level1, const Corridor& level2, const Obstructions& obstructions,
                         const TimedVolume& v) {
  return checkVolume(level1, level2, obstructions, v, obstructions.options().horizon_m);
}

FenceVerdict checkVolume(const Corridor& level1, const Corridor& level2, const Obstructions& obstructions,
                         const TimedVolume& v, double horizon_m) {
  FenceVerdict out;
  checkVolume(level1, level2, obstructions, v, horizon_m, out);
  return out;
}

void checkVolume(const Corridor& level1, const Corridor& level2, const Obstructions& obstructions, const TimedVolume& v,
                 double horizon_m, FenceVerdict& out) {
  const double tol = obstructions.options().tolerance_m;
  std::optional<Check> keep_in = obstructions.keepIn(v);
  out.checks.clear();  // the storage stays: no allocation per check once it has grown
  out.verdict = Verdict::kInside;
  out.violated.reset();
  out.deciding.reset();
  const auto [in1, in2] = level1.containsWith(level2, v.volume, tol);
  out.checks.push_back(boxCheck(Level::kCorridor, in1));
  out.checks.push_back(boxCheck(Level::kAirspace, in2));
  if (keep_in) out.checks.push_back(std::move(*keep_in));
  obstructions.appendChecks(v, horizon_m, out.checks);

  for (int wanted : {2, 1}) {
    for (std::size_t i = 0; i < out.checks.size() && !out.deciding; ++i) {
      if (severity(out.checks[i].verdict) == wanted) out.deciding = i;
    }
  }
  if (out.deciding) {
    out.verdict = out.checks[*out.deciding].verdict;
    out.violated = out.checks[*out.deciding].level;
  }
}

FenceVerdict Fence::check(const TimedVolume& v) const { return checkVolume(level1_, level2_, obstructions_, v); }

void Fence::check(const TimedVolume& v, FenceVerdict& out) const {
  checkVolume(level1_, level2_, obstructions_, v, obstructions_.options().horizon_m, out);
}

std::vector<FenceVerdict> Fence::check(const std::vector<TimedVolume>& samples) const {
  std::vector<FenceVerdict> out;
  out.reserve(samples.size());
  for (const TimedVolume& s : samples) out.push_back(check(s));
  return out;
}

}  // namespace skylane::geofence
