#include "geofence/fence.hpp"

#include "geofence/zone_heights.hpp"

#include "airspace/applicability.hpp"
#include "maps/geodesy.hpp"

#include <algorithm>
#include <charconv>
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

/// This thread's spare checks: those a list held beyond the ones filled again (CheckSlots), the
/// one of the lowest slot last, their strings keeping their storage for a longer list.
std::vector<Check>& spareChecks() {
  thread_local std::vector<Check> spare;
  return spare;
}

/// `c` as a new check, its strings' storage kept.
void resetCheck(Check& c) {
  // Member by member (once per check of every fix); a member added to Check changes its size and
  // stops the build here until it is reset too.
  static_assert(sizeof(void*) != 8 || sizeof(Check) == 152, "a member was added to Check: reset it below, then this size");
  c.level = Level::kCorridor;
  c.verdict = Verdict::kInside;
  c.index = 0;
  c.subject.clear();
  c.name.clear();
  c.restriction.clear();
  c.margin_h_m = c.margin_v_m = 0.0;
  c.clearance_m.reset();
  c.across_joint = c.exact = false;
}

/// The check of one box level into `out` (reset): its deciding segment ("segment N").
void fillBoxCheck(Level level, const Containment& c, Check& out) {
  out.level = level;
  out.verdict = c.verdict;
  out.index = c.segment;
  out.subject.assign("segment ");
  char digits[24];
  const auto r = std::to_chars(digits, digits + sizeof digits, c.segment);
  out.subject.append(digits, static_cast<std::size_t>(r.ptr - digits));
  out.margin_h_m = c.margin_h_m;
  out.margin_v_m = c.margin_v_m;
  out.across_joint = c.across_joint;
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

CheckSlots::~CheckSlots() {
  if (!finished_ && checks_.size() > used_) checks_.resize(used_);
}

Check& CheckSlots::next() {
  if (used_ < checks_.size()) {
    resetCheck(checks_[used_]);
    return checks_[used_++];
  }
  std::vector<Check>& spare = spareChecks();
  if (spare.empty()) {
    ++used_;
    return checks_.emplace_back();
  }
  Check& c = checks_.emplace_back(std::move(spare.back()));
  spare.pop_back();
  resetCheck(c);
  ++used_;
  return c;
}

void CheckSlots::finish() {
  std::vector<Check>& spare = spareChecks();
  for (std::size_t k = checks_.size(); k > used_; --k) spare.push_back(std::move(checks_[k - 1]));
  checks_.resize(used_);
  finished_ = true;
}

void Obstructions::fillHitCheck(const SceneHit& h, Check& c) const {
  const Separation& s = h.separation;
  c.level = h.owner == PieceOwner::kZone ? Level::kZone : Level::kObstacle;
  c.index = h.owner_index;
  if (c.level == Level::kZone) {
    const airspace::Zone& z = zones_[h.owner_index];
    c.subject.assign(z.identifier);
    c.name.assign(z.name);
    c.restriction.assign(airspace::restrictionLabel(z));
  } else {
    c.subject.assign(buildings_[h.owner_index].feature);
  }
  c.margin_h_m = s.margin_h_m;
  c.margin_v_m = s.margin_v_m;
  c.clearance_m = s.clearance_m;
  c.exact = s.exact;
  // The narrow phase has the last word on meeting; the margin says how close it is.
  const double deciding_m = std::max(s.margin_h_m, s.margin_v_m);
  c.verdict = s.meets ? (deciding_m >= -options_.tolerance_m ? Verdict::kIndeterminate : Verdict::kOutside)
                      : (deciding_m <= options_.tolerance_m ? Verdict::kIndeterminate : Verdict::kInside);
}

void Obstructions::appendChecks(const TimedVolume& v, double horizon_m, std::vector<Check>& out) const {
  CheckSlots slots(out, out.size());
  appendChecks(v, horizon_m, slots);
  slots.finish();
}

void Obstructions::appendChecks(const TimedVolume& v, double horizon_m, CheckSlots& slots) const {
  const std::optional<ProtectionVolume> volume = sceneVolume(v.volume);
  if (!volume) return;
  thread_local std::vector<SceneHit> hits;  // this thread's scratch: no allocation once grown
  scene_.query(*volume, horizon_m, [&](PieceOwner owner, std::size_t i) { return takes(owner, i, v); }, hits);
  // One check per zone or obstacle, from the piece that decides it.
  const std::size_t first = slots.size();
  for (const SceneHit& h : hits) fillHitCheck(h, slots.next());
  const auto begin = slots.checks().begin();
  stableSortByInsertion(begin + static_cast<std::ptrdiff_t>(first), begin + static_cast<std::ptrdiff_t>(slots.size()),
                        [](const Check& a, const Check& b) {
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

void Obstructions::fillKeepInCheck(const KeepInMargins& m, const std::vector<const KeepInVolume*>& active,
                                   Check& c) const {
  const airspace::Zone& z = zones_[active[m.nearest]->zone];
  c.level = Level::kKeepIn;
  c.index = active[m.nearest]->zone;
  c.subject.assign(z.identifier);
  c.name.assign(z.name);
  c.restriction.assign(airspace::restrictionLabel(z));
  c.margin_h_m = m.margin_h_m;
  c.margin_v_m = m.margin_v_m;
  c.verdict = keepInVerdict(m);
}

std::optional<Check> Obstructions::keepIn(const TimedVolume& v) const {
  thread_local std::vector<const KeepInVolume*> active;  // this thread's scratch
  const std::optional<KeepInMargins> m = keepInMarginsAt(v, active);
  if (!m) return std::nullopt;
  Check c;
  fillKeepInCheck(*m, active, c);
  return c;
}

void Obstructions::appendKeepIn(const TimedVolume& v, CheckSlots& slots) const {
  thread_local std::vector<const KeepInVolume*> active;  // this thread's scratch
  const std::optional<KeepInMargins> m = keepInMarginsAt(v, active);
  if (m) fillKeepInCheck(*m, active, slots.next());
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
  CheckSlots slots(out.checks);  // filled again in place: no allocation once grown
  out.verdict = Verdict::kInside;
  out.violated.reset();
  out.deciding.reset();
  const auto [in1, in2] = level1.containsWith(level2, v.volume, tol);
  fillBoxCheck(Level::kCorridor, in1, slots.next());
  fillBoxCheck(Level::kAirspace, in2, slots.next());
  obstructions.appendKeepIn(v, slots);
  obstructions.appendChecks(v, horizon_m, slots);
  slots.finish();

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
