#include "planner/approval.hpp"
#include "planner/approval_impl.hpp"

#include "geofence/obstruction_files.hpp"
#include "integrity/predict.hpp"
#include "maps/geoid.hpp"
#include "maps/parse_error.hpp"
#include "maps/plane_frame.hpp"
#include "maps/sky_mask.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

namespace skylane::planner {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Least radius round a replan's start within which only the vehicle's point must be clear [m].
constexpr double kMinExempt_m = 10.0;

std::string fmtMetres(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << v << " m";
  return s.str();
}

std::string fmtTime(double t_s) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(0);
  s << "t+" << t_s << " s";
  return s.str();
}

/// φ(r) of the file comment: grows without bound as PL approaches the alert limit.
double integrityPenalty(double r) {
  if (!(r < 0.99)) return 1e4;
  const double q = r / (1.0 - r);
  return q * q;
}

}  // namespace

Approver::Impl::Impl(Mission mission)
    : m(std::move(mission)),
      frame(m.points.front().lat_rad, m.points.front().lon_rad),
      terrain(m.terrain_file.empty() ? maps::Terrain::flat(m.ground_amsl_m) : maps::Terrain::fromRaster(m.terrain_file)) {
  try {
    limits = geofence::alertLimits(m.vehicle, m.levels);
  } catch (const std::invalid_argument& e) {
    throw maps::ParseError(m.source, 0, "$.k1/$.k2/$.vehicle", "", e.what());
  }
  const auto format = airspace::parseZoneFormat(m.zone_format);
  if (!format) throw maps::ParseError(m.source, 0, "$.zone_format", m.zone_format, "auto, ed269, ed318, geojson or qgc");
  geofence::ZonePolicy policy;
  policy.authorisations = m.authorisations;
  geofence::FenceOptions options;
  options.horizon_m = 500.0;  // zones within 500 m are reported with their clearance
  obstructions = std::make_unique<geofence::Obstructions>(
      geofence::loadObstructions({m.zone_files, *format, m.buildings_file}, frame, terrain, policy, options));
  if (!obstructions->buildings().empty()) {
    const maps::Geodetic origin{m.points.front().lat_rad, m.points.front().lon_rad, 0.0};
    index = std::make_unique<maps::BuildingIndex>(obstructions->buildings(), origin);
  }
  orbits = integrity::loadOrbitFiles(m.orbit_files, m.source, "$.orbits");
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
  const auto g = ground(p.head<2>());
  if (!g) return false;
  const double agl = p.z() - *g;
  if (agl < m.min_agl_m || agl > m.max_agl_m) return false;
  if (m.max_amsl_m) {
    const maps::Geodetic q = geodetic(p);
    if (maps::Geoid::egm96().amslFromEllipsoidal_m(q.lat_rad, q.lon_rad, p.z()) > *m.max_amsl_m) return false;
  }
  for (const auto& [c, r] : penalties) {
    if ((p - c).norm() < r) return false;
  }
  const geofence::TimedVolume v{t0, t1, planningVolume(p)};
  return !obstructions->firstConflict(v);
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
  return integrity::predictAt(orbits, req, t, m.method);
}

double Approver::Impl::ratioOf(const integrity::PredictSample& s) const {
  if (!s.pl.pl_computed) return kInf;
  return std::max(s.pl.hpl_m / limits.level2.hal_m, s.pl.vpl_m / limits.level2.val_m);
}

void Approver::Impl::buildCostGrid(const maps::GpsTime& t_mid) {
  cell_m = m.cost_cell_m;
  while ((upper.x() - lower.x()) * (upper.y() - lower.y()) / (cell_m * cell_m) > 20000.0) cell_m *= 1.5;
  cols = std::max(1, static_cast<int>(std::ceil((upper.x() - lower.x()) / cell_m)));
  rows = std::max(1, static_cast<int>(std::ceil((upper.y() - lower.y()) / cell_m)));
  const std::size_t n = static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
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

std::size_t Approver::Impl::cellOf(const Eigen::Vector3d& p) const {
  const int c = std::clamp(static_cast<int>((p.x() - lower.x()) / cell_m), 0, cols - 1);
  const int r = std::clamp(static_cast<int>((p.y() - lower.y()) / cell_m), 0, rows - 1);
  return static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c);
}

geofence::ProtectionVolume Approver::Impl::planningVolume(const Eigen::Vector3d& p) const {
  double h = limits.level1.hal_m, v = limits.level1.val_m;
  if (!grid_pl.empty()) {
    const Eigen::Vector2d& pl = grid_pl[cellOf(p)];
    if (std::isfinite(pl.x())) {
      h = std::max(h, 1.2 * pl.x());
      v = std::max(v, 1.2 * pl.y());
    }
  }
  return {p, h, v};
}

double Approver::Impl::extraCost(const Eigen::Vector3d& p) const { return cost[cellOf(p)]; }

std::vector<RoutePoint> Approver::Impl::timeRoute(const std::vector<Eigen::Vector3d>& pts) const {
  std::vector<RoutePoint> out;
  double t = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i > 0) {
      const Eigen::Vector3d d = pts[i] - pts[i - 1];
      t += std::max(d.head<2>().norm() / m.cruise_speed_mps, std::abs(d.z()) / m.climb_speed_mps);
    }
    RoutePoint rp;
    rp.xyz = pts[i];
    const maps::Geodetic g = geodetic(pts[i]);
    rp.lat_rad = g.lat_rad;
    rp.lon_rad = g.lon_rad;
    rp.h_ell_m = g.h_ell_m;
    rp.alt_amsl_m = maps::Geoid::egm96().amslFromEllipsoidal_m(g.lat_rad, g.lon_rad, g.h_ell_m);
    rp.eta_s = t;
    out.push_back(rp);
  }
  return out;
}

Eigen::Vector3d positionAlong(const std::vector<RoutePoint>& route, double t_s) {
  if (route.empty()) throw std::invalid_argument("positionAlong: an empty route");
  if (t_s <= route.front().eta_s) return route.front().xyz;
  for (std::size_t i = 1; i < route.size(); ++i) {
    if (t_s <= route[i].eta_s) {
      const double span = route[i].eta_s - route[i - 1].eta_s;
      const double f = span > 0 ? (t_s - route[i - 1].eta_s) / span : 1.0;
      return route[i - 1].xyz + f * (route[i].xyz - route[i - 1].xyz);
    }
  }
  return route.back().xyz;
}

Approver::Approver(Mission mission) : impl_(std::make_unique<Impl>(std::move(mission))) {}
Approver::~Approver() = default;
const Mission& Approver::mission() const { return impl_->m; }
const maps::PlaneFrame& Approver::frame() const { return impl_->frame; }
const geofence::Obstructions& Approver::obstructions() const { return *impl_->obstructions; }
const integrity::OrbitSource& Approver::orbits() const { return impl_->orbits; }

std::vector<Eigen::Vector3d> Approver::missionStops() const {
  const Mission& m = impl_->m;
  std::vector<Eigen::Vector3d> stops;
  for (const MissionPoint& p : m.points) {
    const Eigen::Vector2d xy = impl_->frame.toPlane(p.lat_rad, p.lon_rad);
    const auto g = impl_->ground(xy);
    if (!g) {
      throw maps::ParseError(m.source, 0, m.qgc_plan_file.empty() ? "$.start/$.waypoints/$.goal" : "$.qgc_plan", "",
                             "route points the terrain model covers");
    }
    stops.emplace_back(xy.x(), xy.y(), *g + m.cruise_agl_m);
  }
  return stops;
}

ApprovalReport Approver::approve(const std::function<void(const std::string&)>& progress) {
  const Mission& m = impl_->m;
  std::vector<maps::GpsTime> departures;
  for (double dt = 0.0; dt <= (m.departure_latest - m.departure_earliest) + 1e-6; dt += m.departure_step_s) {
    departures.push_back(m.departure_earliest.plus(dt));
  }
  return impl_->run(missionStops(), departures, false, progress);
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
  return impl_->run(stops, {now}, true, progress);
}

ApprovalReport Approver::Impl::run(const std::vector<Eigen::Vector3d>& stops, const std::vector<maps::GpsTime>& departures,
                                   bool from_vehicle, const std::function<void(const std::string&)>& progress) {
  Impl& d = *this;
  const auto started = std::chrono::steady_clock::now();
  auto say = [&progress](const std::string& s) {
    if (progress) progress(s);
  };
  ApprovalReport report;
  report.limits = d.limits;
  double direct_m = 0.0;
  for (std::size_t i = 1; i < stops.size(); ++i) direct_m += (stops[i] - stops[i - 1]).head<2>().norm();
  const double direct_s = direct_m / m.cruise_speed_mps;
  const double flight_bound_s = 2.0 * direct_s + 120.0;
  // The zones' activity window reaches the mission's latest departure (a window whose length
  // is not a multiple of its step has its last departure before it); a replan's is `now`.
  const maps::GpsTime latest_departure = from_vehicle ? departures.back() : m.departure_latest;

  const bool with_masks = d.masked();
  if (!cost_grid_built) {
    say("predicted protection levels over the area (integrity cost field)");
    d.buildCostGrid(departures.front().plus(direct_s / 2.0));
    cost_grid_built = true;
  }
  // From the vehicle: the search box reaches it, and near it only the vehicle's own point must be
  // clear (it may have drifted so close to a zone that its box is not: the route leads it away).
  Eigen::Vector3d box_lo = d.lower, box_hi = d.upper;
  double exempt_m = 0.0;
  if (from_vehicle) {
    box_lo = box_lo.cwiseMin(stops.front() - Eigen::Vector3d::Constant(1.0));
    box_hi = box_hi.cwiseMax(stops.front() + Eigen::Vector3d::Constant(1.0));
    exempt_m = std::max(kMinExempt_m, 2.0 * d.planningVolume(stops.front()).hpl_m);
  }

  std::vector<approval_steps::Penalty> penalties;
  std::vector<Reason> last_reasons;
  std::vector<RoutePoint> last_route;
  approval_steps::RouteSamples last_samples;
  for (const maps::GpsTime& dep : departures) {
    ++report.planner.departures_tried;
    for (int attempt = 0; attempt <= m.max_replans; ++attempt) {
      ++report.planner.attempts;
      say("planning (departure " + maps::formatRfc3339(dep) + ", attempt " + std::to_string(attempt + 1) + ")");
      // Plan leg by leg through the waypoints.
      std::vector<Eigen::Vector3d> pts{stops.front()};
      PathResult last;
      bool ok = true;
      std::size_t failed_leg = 0;
      for (std::size_t leg = 1; leg < stops.size() && ok; ++leg) {
        failed_leg = leg;
        PathProblem prob;
        prob.lower_enu_m = box_lo;
        prob.upper_enu_m = box_hi;
        prob.start_enu_m = pts.back();
        prob.goal_enu_m = stops[leg];
        const Eigen::Vector2d start_xy = stops.front().head<2>();
        const maps::GpsTime latest = latest_departure.plus(flight_bound_s);
        const Eigen::Vector3d vehicle = stops.front();
        prob.is_valid = [&d, &penalties, start_xy, dep, latest, this, vehicle, exempt_m](const Eigen::Vector3d& p) {
          const maps::GpsTime earliest = dep.plus((p.head<2>() - start_xy).norm() / m.cruise_speed_mps);
          if (exempt_m > 0.0 && (p - vehicle).norm() <= exempt_m) {
            return !d.obstructions->firstConflict({earliest, latest, {p, 0.0, 0.0}});
          }
          return d.valid(p, earliest, latest, penalties);
        };
        if (!d.cost.empty()) {
          prob.extra_cost = [&d](const Eigen::Vector3d& p) { return d.extraCost(p); };
          prob.cost_step_m = d.cell_m / 2.0;
        }
        prob.resolution_m = m.resolution_m;
        prob.time_limit_s = m.time_limit_s;
        prob.max_iterations = m.iterations;
        prob.seed = m.seed + static_cast<std::uint64_t>(attempt) * 7919u + leg;
        prob.planner = m.planner;
        prob.simplify = m.simplify;
        last = planPath(prob);
        report.planner.planning_time_s += last.planning_time_s + last.simplify_time_s;
        report.planner.iterations += last.iterations;
        report.planner.stopped_by_time = report.planner.stopped_by_time || last.stopped_by_time;
        if (last.status != PathStatus::kExact) {
          ok = false;
          break;
        }
        pts.insert(pts.end(), last.points.begin() + 1, last.points.end());
      }
      report.planner.algorithm = std::string(plannerName(m.planner));
      report.planner.status = std::string(pathStatusName(last.status));
      report.planner.straight_line = last.straight_line && stops.size() == 2;
      if (!ok) {
        Reason r;
        r.kind = "planning";
        r.subject = report.planner.status;
        if (last.status == PathStatus::kInvalidStart || last.status == PathStatus::kInvalidGoal) {
          const bool start = last.status == PathStatus::kInvalidStart;
          const Eigen::Vector3d p = start ? pts.back() : stops[failed_leg];
          r.message = std::string(start ? "the start" : "the goal") +
                      " is not flyable at cruise height: it is inside (or within the level-1 box of) an active zone"
                      " or obstacle, or outside the altitude limits";
          if (const auto c = d.obstructions->firstConflict(
                  {dep, latest_departure.plus(flight_bound_s), {p, d.limits.level1.hal_m, d.limits.level1.val_m}})) {
            r.kind = c->level == geofence::Level::kZone ? "zone" : "obstacle";
            r.subject = c->subject;
            r.message = std::string(start ? "the start" : "the goal") + " lies in " +
                        (c->level == geofence::Level::kZone ? "zone " : "obstacle ") + c->subject;
          }
          const maps::Geodetic g = d.geodetic(p);
          r.lat_rad = g.lat_rad;
          r.lon_rad = g.lon_rad;
          r.h_ell_m = g.h_ell_m;
        } else {
          r.message = "no route found within " + std::to_string(last.iterations) + " planner iterations (" +
                      report.planner.status + (last.stopped_by_time ? ", stopped by the time limit)" : ")");
        }
        last_reasons = {r};
        last_route.clear();
        break;  // replanning cannot help; next departure
      }

      // Time, sample and check the route.
      std::vector<RoutePoint> route = d.timeRoute(pts);
      report.planner.length_m = polylineLength(pts);
      const double total_s = route.back().eta_s;
      approval_steps::RouteSamples samples;
      for (double t = 0.0;; t += m.sample_s) {
        const double tt = std::min(t, total_s);
        samples.t_s.push_back(tt);
        if (tt >= total_s) break;
      }
      say("predicting " + std::to_string(samples.t_s.size()) + " samples");
      for (double t : samples.t_s) {
        const Eigen::Vector3d p = positionAlong(route, t);
        samples.xyz.push_back(p);
        samples.geo.push_back(d.geodetic(p));
        samples.masks.push_back(with_masks ? std::optional(d.skyMaskAt(samples.geo.back())) : std::nullopt);
      }
      const geofence::Corridor level1(pts, d.limits.level1, {});
      const geofence::Corridor level2(pts, d.limits.level2, {});
      // The fence borrows the obstructions: a copy would rebuild the scene.
      std::vector<Reason> reasons;
      std::vector<int> occurrences;   // per reason: samples concerned
      std::vector<double> first_t;    // per reason: first sample time
      std::vector<PredictedSample> predicted;
      int level1_exceedances = 0;
      std::vector<approval_steps::Penalty> violations;
      for (std::size_t k = 0; k < samples.t_s.size(); ++k) {
        PredictedSample ps;
        ps.t_s = samples.t_s[k];
        ps.xyz = samples.xyz[k];
        ps.lat_rad = samples.geo[k].lat_rad;
        ps.lon_rad = samples.geo[k].lon_rad;
        ps.h_ell_m = samples.geo[k].h_ell_m;
        const maps::GpsTime t = dep.plus(ps.t_s);
        const integrity::PredictSample pr = d.predictAt(samples.geo[k], t, samples.masks[k]);
        ps.pl_available = pr.pl.pl_computed;
        ps.hpl_m = pr.pl.hpl_m;
        ps.vpl_m = pr.pl.vpl_m;
        ps.satellites = static_cast<int>(pr.sats.size());
        ps.blocked = static_cast<int>(pr.blocked);
        auto addReason = [&](Reason r) {
          r.t_s = ps.t_s;
          r.lat_rad = ps.lat_rad;
          r.lon_rad = ps.lon_rad;
          r.h_ell_m = ps.h_ell_m;
          // One reason per kind and subject: where and when it is worst, and from when.
          for (std::size_t i = 0; i < reasons.size(); ++i) {
            Reason& e = reasons[i];
            if (e.kind != r.kind || e.subject != r.subject) continue;
            ++occurrences[i];
            if (r.value_m && e.value_m && *r.value_m > *e.value_m) {
              const double first = first_t[i];
              e = std::move(r);
              first_t[i] = first;
            }
            return;
          }
          reasons.push_back(std::move(r));
          occurrences.push_back(1);
          first_t.push_back(ps.t_s);
        };
        if (!ps.pl_available) {
          Reason r;
          r.kind = "integrity";
          r.subject = "PL";
          r.message = "no protection level: " + std::to_string(ps.satellites) + " satellites usable (" +
                      std::to_string(ps.blocked) + " hidden by buildings or terrain)";
          addReason(r);
          violations.emplace_back(ps.xyz, 50.0);
          predicted.push_back(std::move(ps));
          continue;
        }
        // The fence: both levels, zones and obstacles at this instant.
        const geofence::TimedVolume v{t, t, {ps.xyz, ps.hpl_m, ps.vpl_m}};
        geofence::FenceVerdict fv = geofence::checkVolume(level1, level2, *d.obstructions, v);
        for (const geofence::Check& c : fv.checks) {
          if (c.level == geofence::Level::kCorridor) {
            // Level 1 is not a rejection: in flight HPL > HAL₁ reruns the monitoring.
            if (c.verdict != geofence::Verdict::kInside) ++level1_exceedances;
            continue;
          }
          if (c.level == geofence::Level::kAirspace) {
            if (c.verdict == geofence::Verdict::kInside) continue;
            Reason r;
            r.kind = "airspace";
            const bool horizontal = c.margin_h_m < c.margin_v_m;
            r.subject = horizontal ? "HPL" : "VPL";
            r.value_m = horizontal ? ps.hpl_m : ps.vpl_m;
            r.limit_m = horizontal ? d.limits.level2.hal_m : d.limits.level2.val_m;
            r.message = std::string(horizontal ? "HPL " : "VPL ") + fmtMetres(*r.value_m) + " exceeds the level-2 limit " +
                        fmtMetres(*r.limit_m) + " by " + fmtMetres(*r.value_m - *r.limit_m);
            addReason(r);
            violations.emplace_back(ps.xyz, std::min(300.0, std::max(ps.hpl_m, 20.0)));
            continue;
          }
          // A replan's first metres leave the place the vehicle is in; they are not its reasons.
          const bool leaving = from_vehicle && (ps.xyz - stops.front()).norm() <= exempt_m;
          if (c.verdict != geofence::Verdict::kInside && !leaving) {
            Reason r;
            r.kind = c.level == geofence::Level::kZone ? "zone" : "obstacle";
            r.subject = c.subject;
            r.value_m = -std::max(c.margin_h_m, c.margin_v_m);
            r.message = std::string("the protection volume (HPL ") + fmtMetres(ps.hpl_m) + ", VPL " + fmtMetres(ps.vpl_m) +
                        ") meets " + (c.level == geofence::Level::kZone ? "zone " : "obstacle ") + c.subject + " at " +
                        fmtTime(ps.t_s) + "; it must shrink by " + fmtMetres(*r.value_m);
            addReason(r);
            violations.emplace_back(ps.xyz, std::min(300.0, std::max(ps.hpl_m, 20.0)) + d.limits.level1.hal_m);
          }
          if (c.level == geofence::Level::kZone) {
            auto it = std::find_if(report.zones.begin(), report.zones.end(),
                                   [&](const ZoneApproach& z) { return z.identifier == c.subject; });
            if (it == report.zones.end()) {
              const airspace::Zone& z = d.obstructions->zones()[c.index];
              report.zones.push_back({z.identifier, std::string(airspace::restrictionName(z.restriction)),
                                      d.obstructions->zoneCounts(c.index), *c.clearance_m});
            } else {
              it->min_clearance_m = std::min(it->min_clearance_m, *c.clearance_m);
            }
          }
        }
        ps.fence = std::move(fv);
        predicted.push_back(std::move(ps));
      }
      for (std::size_t i = 0; i < reasons.size(); ++i) {
        if (occurrences[i] > 1) {
          reasons[i].message += " (worst of " + std::to_string(occurrences[i]) + " samples from " + fmtTime(first_t[i]) + ")";
        }
      }
      last_route = route;
      last_samples = samples;
      report.route = route;
      report.predicted = std::move(predicted);
      report.level1_exceedances = level1_exceedances;
      report.departure = dep;
      if (reasons.empty()) {
        report.approved = true;
        report.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        return report;
      }
      last_reasons = reasons;
      penalties.insert(penalties.end(), violations.begin(), violations.end());
    }
  }

  // Rejected: the last attempt's reasons; for a fixed departure, the earliest later departure
  // (within 24 h, in departure steps) at which the same route passes its integrity checks.
  report.approved = false;
  report.reasons = last_reasons;
  if (!last_route.empty() && departures.size() == 1 && !from_vehicle) {
    say("looking for a later departure");
    std::vector<Eigen::Vector3d> pts;
    for (const RoutePoint& p : last_route) pts.push_back(p.xyz);
    const geofence::Corridor level1(pts, d.limits.level1, {});
    const geofence::Corridor level2(pts, d.limits.level2, {});
    for (double shift = m.departure_step_s; shift <= 86400.0; shift += m.departure_step_s) {
      const maps::GpsTime dep = departures.front().plus(shift);
      bool pass = true;
      for (std::size_t k = 0; k < last_samples.t_s.size() && pass; ++k) {
        const maps::GpsTime t = dep.plus(last_samples.t_s[k]);
        const integrity::PredictSample pr = d.predictAt(last_samples.geo[k], t, last_samples.masks[k]);
        if (!pr.pl.pl_computed) {
          pass = false;
          break;
        }
        // The same rule as the approval: every check but level 1 must hold.
        const geofence::TimedVolume v{t, t, {last_samples.xyz[k], pr.pl.hpl_m, pr.pl.vpl_m}};
        for (const geofence::Check& c : geofence::checkVolume(level1, level2, *d.obstructions, v).checks) {
          if (c.level != geofence::Level::kCorridor && c.verdict != geofence::Verdict::kInside) pass = false;
        }
      }
      if (pass) {
        report.earliest_passing_departure = dep;
        break;
      }
    }
  }
  report.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

}  // namespace skylane::planner
