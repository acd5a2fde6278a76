// The protection levels along a route for the mission's navigation (GNSS alone, GNSS/INS, a
// receiver's declared PLs), each box level's availability over the route's samples, and the
// policy's minimum level-1 availability (approval.hpp, steps 3 and 4).
#include "planner/approval_impl.hpp"
#include "planner/ins_pl_prediction.hpp"
#include "planner/report_formats.hpp"

#include "integrity/ins/filter_tuning.hpp"

#include <cmath>
#include <sstream>

namespace skylane::planner {

using approval_steps::RouteSamples;

namespace {

std::string seconds(double t_s) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(0);
  s << t_s;
  return s.str();
}

std::string latLon(double lat_rad, double lon_rad) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(5);
  s << maps::rad2deg(lat_rad) << "°, " << maps::rad2deg(lon_rad) << "°";
  return s.str();
}

/// A sample holds a level when it has PLs within both of the level's limits.
bool holds(const PredictedSample& s, const geofence::AlertLimits& limits) {
  return s.pl_available && s.hpl_m <= limits.hal_m && s.vpl_m <= limits.val_m;
}

}  // namespace

LevelAvailability levelAvailability(const std::vector<PredictedSample>& samples, const geofence::AlertLimits& limits) {
  LevelAvailability a;
  a.limits = limits;
  a.samples = static_cast<int>(samples.size());
  std::optional<FailingStretch> run;
  auto close = [&a, &run] {
    if (run && (!a.worst_stretch || run->samples > a.worst_stretch->samples)) a.worst_stretch = run;
    run.reset();
  };
  for (const PredictedSample& s : samples) {
    if (holds(s, limits)) {
      ++a.held;
      close();
      continue;
    }
    if (!run) run = FailingStretch{s.t_s, s.t_s, s.lat_rad, s.lon_rad, s.lat_rad, s.lon_rad, 0};
    run->t_end_s = s.t_s;
    run->lat_end_rad = s.lat_rad;
    run->lon_end_rad = s.lon_rad;
    ++run->samples;
  }
  close();
  a.fraction = a.samples > 0 ? static_cast<double>(a.held) / a.samples : 0.0;
  return a;
}

std::vector<PredictedSample> Approver::Impl::predictRoute(const std::vector<RoutePoint>& route, const RouteSamples& samples,
                                                          const maps::GpsTime& departure) const {
  std::vector<PredictedSample> out;
  out.reserve(samples.t_s.size());
  // GNSS alone and a receiver's declared PLs: each sample on its own (predictAt).
  for (std::size_t k = 0; k < samples.t_s.size(); ++k) out.push_back(predictSample(samples, k, departure.plus(samples.t_s[k])));
  if (m.navigation.kind == NavigationKind::kGnssIns) applyInsPrediction(route, samples, departure, out);
  return out;
}

/// GNSS/INS: the tracker's filter flown along the route (planner/ins_pl_prediction.hpp) replaces
/// the samples' PLs and satellite counts.
void Approver::Impl::applyInsPrediction(const std::vector<RoutePoint>& route, const RouteSamples& samples,
                                        const maps::GpsTime& departure, std::vector<PredictedSample>& out) const {
  InsPredictionInput in;
  in.departure = departure;
  in.duration_s = route.back().eta_s;
  in.where = [this, &route](double t_s) { return geodetic(positionAlong(route, t_s)); };
  in.sample_t_s = samples.t_s;
  in.outside_sky_mask = [&samples](std::size_t k, const maps::LookAngles& look) {
    return !samples.masks[k] || samples.masks[k]->isVisible(look);
  };
  in.config = integrity::ins::trackingNavigatorConfig(m.navigation.imu, m.model, maps::deg2rad(m.mask_deg),
                                                      integrity::ins::kTrackingAlignPositionSigma_m);
  in.imu_rate_hz = integrity::ins::imuSpec(m.navigation.imu).rate_hz;
  const std::vector<InsPredictedPl> pls = predictInsProtectionLevels(orbits, in);
  for (std::size_t k = 0; k < out.size(); ++k) {
    PredictedSample& ps = out[k];
    ps.pl_available = pls[k].available;
    ps.hpl_m = pls[k].hpl_m;
    ps.vpl_m = pls[k].vpl_m;
    ps.satellites = pls[k].satellites;
    ps.blocked = pls[k].blocked;
    if (pls[k].three_hypothesis_available) {
      ps.three_hypothesis_hpl_m = pls[k].three_hypothesis_hpl_m;
      ps.three_hypothesis_vpl_m = pls[k].three_hypothesis_vpl_m;
    }
  }
}

std::optional<Reason> Approver::Impl::availabilityShortfall(const LevelAvailability& level1) const {
  const std::optional<double>& minimum = m.policy.min_level1_availability;
  if (!minimum || level1.fraction >= *minimum) return std::nullopt;
  Reason r;
  r.kind = "availability";
  r.subject = "level 1";
  std::ostringstream msg;
  msg.setf(std::ios::fixed);
  msg.precision(1);
  msg << "the corridor (level 1, HAL₁ " << level1.limits.hal_m << " m, VAL₁ " << level1.limits.val_m << " m) holds at "
      << availabilityPercent(level1.fraction) << " of samples, below the policy's " << availabilityPercent(*minimum);
  if (const auto& w = level1.worst_stretch) {
    msg << "; the longest stretch without it is " << w->samples << " samples from t+" << seconds(w->t_start_s) << " s to t+"
        << seconds(w->t_end_s) << " s (" << seconds(w->duration_s()) << " s), from " << latLon(w->lat_start_rad, w->lon_start_rad)
        << " to " << latLon(w->lat_end_rad, w->lon_end_rad);
    r.t_s = w->t_start_s;
    r.lat_rad = w->lat_start_rad;
    r.lon_rad = w->lon_start_rad;
  }
  r.message = msg.str();
  return r;
}

}  // namespace skylane::planner
