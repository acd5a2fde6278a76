#include "integrity/raim/live_fix.hpp"

#include "integrity/araim/exclusion.hpp"
#include "integrity/araim/fde.hpp"
#include "integrity/gnss/atmosphere.hpp"
#include "integrity/raim/wls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace skylane::integrity {
namespace {

constexpr int kMaxIterations = 12;
/// A position step below this ends the iteration (far below any PL; WLS converges in 3–4 steps).
constexpr double kConvergence_m = 1e-4;
/// Below this radius a linearisation point is not on or above the Earth (no usable start).
constexpr double kMinEarthRadius_m = 6.0e6;

using Located = LocatedRange;

/// The linearised problem at a converged point.
struct Linearised {
  bool ok = false;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  ///< the solution (last point plus its last step)
  maps::Geodetic user;                          ///< the last linearisation point
  std::array<double, kNumConstellations> clock{};  ///< receiver clocks at the solution [m]
  Geometry g;
  Eigen::VectorXd y;          ///< prefit residuals at the last linearisation point
  WlsSolution wls;            ///< solveWls(g.G, g.sigma_int), when converge() made it
  std::vector<int> index;     ///< per geometry row: index into the located ranges
};

/// One linearisation at x: the geometry of the active ranges above the mask and their prefit
/// residuals (the clocks start, on the first call, at each constellation's mean residual).
Linearised linearise(const std::vector<Located>& located, const std::vector<int>& active, const Eigen::Vector3d& x,
                     const LiveFixConfig& cfg, std::array<double, kNumConstellations>& clock, bool& clocks_set) {
  Linearised out;
  const maps::Geodetic user = maps::ecefToGeodetic(x);
  const Eigen::Matrix3d r_enu_ecef = maps::rotationEcefToEnu(user.lat_rad, user.lon_rad);
  const double tau = cfg.model.iono_tau_vert_m.value_or(ionoTauVert_m(geomagneticLatitude(user)));
  std::vector<SatLook> looks;
  std::vector<double> ranges;
  looks.reserve(active.size());
  ranges.reserve(active.size());
  out.index.reserve(active.size());
  for (int k : active) {
    const Located& s = located[static_cast<std::size_t>(k)];
    const maps::LookAngles look = maps::lookAngles(x, r_enu_ecef, s.sat_ecef_m);
    if (look.elevation_rad < cfg.elevation_mask_rad) continue;
    looks.push_back({s.sat, look});
    ranges.push_back((s.sat_ecef_m - x).norm());
    out.index.push_back(k);
  }
  out.g = buildGeometry(looks, cfg.model, tau);
  const int n = out.g.numSats();
  if (n < out.g.numStates()) return out;
  auto pr = [&](int i) { return located[static_cast<std::size_t>(out.index[static_cast<std::size_t>(i)])].pr_m; };
  if (!clocks_set) {  // each receiver clock starts at the mean of its constellation's residuals
    for (Constellation c : out.g.clocks) {
      double sum = 0.0;
      int count = 0;
      for (int i = 0; i < n; ++i) {
        if (out.g.sats[static_cast<std::size_t>(i)].constellation != c) continue;
        sum += pr(i) - ranges[static_cast<std::size_t>(i)];
        ++count;
      }
      clock[static_cast<int>(c)] = sum / count;
    }
    clocks_set = true;
  }
  out.y.resize(n);
  for (int i = 0; i < n; ++i) {
    out.y[i] = pr(i) - (ranges[static_cast<std::size_t>(i)] + clock[static_cast<int>(out.g.sats[static_cast<std::size_t>(i)].constellation)]);
  }
  out.ok = true;
  out.x = x;
  out.user = user;
  return out;
}

/// Iterated WLS over `active` (indices into the ranges) from x0, the ranges seen anew from each
/// linearisation point.
Linearised converge(const RangesSeenFrom& ranges_from, const std::vector<int>& active, const Eigen::Vector3d& x0,
                    const LiveFixConfig& cfg) {
  Linearised out;
  Eigen::Vector3d x = x0;
  std::array<double, kNumConstellations> clock{};
  bool clocks_set = false;
  Eigen::VectorXd dx;
  for (int it = 0; it < kMaxIterations; ++it) {
    Linearised lin = linearise(ranges_from(x), active, x, cfg, clock, clocks_set);
    if (!lin.ok) return Linearised{};
    lin.wls = solveWls(lin.g.G, lin.g.sigma_int);
    if (!lin.wls.ok) return Linearised{};
    dx = lin.wls.S * lin.y;
    x = maps::LocalFrame(lin.user).enuToEcef(dx.head<3>());
    out = std::move(lin);
    for (std::size_t c = 0; c < out.g.clocks.size(); ++c) clock[static_cast<int>(out.g.clocks[c])] += dx[3 + static_cast<Eigen::Index>(c)];
    if (dx.head<3>().norm() < kConvergence_m) break;
  }
  out.x = x;  // the last linearisation point plus its (small) last step
  out.clock = clock;
  return out;
}

/// Largest horizontal and vertical shift of the WLS solution when one satellite is left out.
Eigen::Vector2d largestSeparation(const Geometry& g, const Eigen::VectorXd& y) {
  const WlsSolution all = solveWls(g.G, g.sigma_int);
  const Eigen::Vector3d x0 = (all.S * y).head<3>();
  Eigen::Vector2d worst = Eigen::Vector2d::Zero();
  for (int i = 0; i < g.numSats(); ++i) {
    const Geometry gi = g.without(i);
    if (gi.numSats() <= gi.numStates() - 1) continue;
    const WlsSolution wi = solveWls(gi.G, gi.sigma_int);
    if (!wi.ok) continue;
    Eigen::VectorXd yi(y.size() - 1);
    for (Eigen::Index r = 0, j = 0; r < y.size(); ++r) {
      if (r != i) yi[j++] = y[r];
    }
    const Eigen::Vector3d d = (wi.S * yi).head<3>() - x0;
    worst.x() = std::max(worst.x(), d.head<2>().norm());
    worst.y() = std::max(worst.y(), std::abs(d.z()));
  }
  return worst;
}

/// The protection levels of a linearised geometry and its detection test: RAIM the normalised
/// √WSSE against T_d (Brown's χ² test), ARAIM the largest solution separation over its threshold.
struct GeometryCheck {
  PlSummary pl;
  double statistic = 0.0;
  double threshold = 0.0;
  bool fails = false;  ///< the detection test fires
};

GeometryCheck checkGeometry(const Linearised& lin, const LiveFixConfig& cfg) {
  GeometryCheck out;
  if (cfg.method == IntegrityMethod::kAraim) {
    const AraimResult r = araimProtectionLevels(lin.g, cfg.model, cfg.araim);
    out.pl = summarize(r);
    out.threshold = 1.0;
    if (r.pl_computed) out.statistic = solutionSeparationRatio(r, lin.y);
    out.fails = out.statistic > out.threshold;
    return out;
  }
  const WlsSolution& w = lin.wls;
  out.pl = summarize(raimProtectionLevels(lin.g, w, cfg.raim), cfg.araim.requirements);
  const Eigen::VectorXd r = lin.y - lin.g.G * (w.S * lin.y);
  out.statistic = r.cwiseQuotient(lin.g.sigma_int).norm();
  const int dof = lin.g.numSats() - lin.g.numStates();
  if (dof > 0) {
    out.threshold = raimThresholds(dof, cfg.raim.pfa, cfg.raim.pmd).threshold;
    out.fails = out.statistic > out.threshold;
  }
  return out;
}

/// The geometry rows the method's FDE excludes (RAIM: Baarda's w-test, at least one exclusion;
/// ARAIM: solution separation); empty unless the exclusion makes the test pass.
std::vector<int> excludedRows(const Linearised& lin, const LiveFixConfig& cfg) {
  if (cfg.method == IntegrityMethod::kAraim) {
    const AraimFdeResult r = araimFde(lin.g, lin.y, cfg.model, cfg.araim);
    return r.fault_excluded ? r.excluded : std::vector<int>{};
  }
  RaimConfig raim = cfg.raim;
  raim.max_exclusions = std::max(1, cfg.raim.max_exclusions);
  const RaimFdeResult r = raimFde(lin.g, lin.y, raim);
  return r.fault_excluded ? r.excluded : std::vector<int>{};
}

/// The PL and test of the outcome "exclude `excluded`" under ExclusionPl::kAllocated
/// (docs/method.md §3.2a, §4.3): the all-in-view ranges are linearised again at the reduced
/// solution's last point; ARAIM solves the restricted modes of that geometry with ρ·P_HMI and
/// tests the reduced solution against their thresholds T_k,j, RAIM takes the reduced geometry's
/// PL with ρ·P_md and ρ·P_HMI. Without the allocation it is the reduced geometry's own check.
GeometryCheck checkAfterExclusion(const RangesSeenFrom& ranges_from, const std::vector<int>& all, const Linearised& reduced,
                                  const std::vector<SatId>& excluded, const LiveFixConfig& cfg) {
  const bool araim = cfg.method == IntegrityMethod::kAraim;
  if ((araim ? cfg.araim.exclusion_pl : cfg.raim.exclusion_pl) != ExclusionPl::kAllocated) return checkGeometry(reduced, cfg);
  std::array<double, kNumConstellations> clock = reduced.clock;
  bool clocks_set = true;
  const Eigen::Vector3d x = maps::geodeticToEcef(reduced.user);
  const Linearised full = linearise(ranges_from(x), all, x, cfg, clock, clocks_set);
  if (!araim) {
    LiveFixConfig c = cfg;
    const int n_exc = raimExclusionCandidates(full.g.numSats(), full.g.numStates(), std::max(1, cfg.raim.max_exclusions));
    c.raim = outcomeConfig(cfg.raim, 1.0 / (n_exc + 1.0));
    return checkGeometry(reduced, c);
  }
  std::vector<int> rows;
  for (int r = 0; r < full.g.numSats(); ++r) {
    if (std::find(excluded.begin(), excluded.end(), full.g.sats[static_cast<std::size_t>(r)]) != excluded.end()) rows.push_back(r);
  }
  const FaultModeSet modes = araimFaultModes(full.g, cfg.model, cfg.araim);
  const double rho = exclusionBudgetShare(exclusionCandidates(full.g, cfg.model, cfg.araim).size());
  const AraimResult rk = araimLevelsAfterExclusion(full.g, modes, rows, cfg.araim, rho);
  Eigen::VectorXd yk(full.g.numSats() - static_cast<int>(rows.size()));
  for (int r = 0, j = 0; r < full.g.numSats(); ++r) {
    if (!std::binary_search(rows.begin(), rows.end(), r)) yk[j++] = full.y[r];
  }
  GeometryCheck out;
  out.pl = summarize(rk);
  out.threshold = 1.0;
  if (rk.pl_computed) out.statistic = solutionSeparationRatio(rk, yk);
  out.fails = out.statistic > out.threshold;
  return out;
}

/// The range indices of `lin` without its `rows`; their satellites go to `excluded`.
std::vector<int> keptRanges(const Linearised& lin, const std::vector<int>& rows, std::vector<SatId>& excluded) {
  std::vector<int> kept;
  for (std::size_t row = 0; row < lin.index.size(); ++row) {
    if (std::find(rows.begin(), rows.end(), static_cast<int>(row)) == rows.end()) {
      kept.push_back(lin.index[row]);
    } else {
      excluded.push_back(lin.g.sats[row]);
    }
  }
  return kept;
}

/// The solution, its protection levels and test, and — detected, not excluded — PL_det.
void fillSolution(const Linearised& lin, const GeometryCheck& check, LiveFix& out) {
  out.solved = true;
  out.p_ecef = lin.x;
  out.position = maps::ecefToGeodetic(lin.x);
  out.clock_m = lin.g.clocks.empty() ? 0.0 : lin.clock[static_cast<int>(lin.g.clocks[0])];
  out.used = lin.g.sats;
  out.pl = check.pl;
  out.test_statistic = check.statistic;
  out.threshold = check.threshold;
  out.fault_free_hpl_m = out.pl.hpl_m;
  out.fault_free_vpl_m = out.pl.vpl_m;
  if (out.fault_detected && !out.fault_excluded && out.pl.pl_computed) {
    // PL_det of the file comment: the fault-free PL plus the largest leave-one-out shift.
    const Eigen::Vector2d sep = largestSeparation(lin.g, lin.y);
    out.pl.hpl_m += sep.x();
    out.pl.vpl_m += sep.y();
    out.pl.available = false;
    out.pl.reason = "fault detected and not excluded";
    out.note += "fault detected; PL grown by the largest leave-one-out shift";
  }
}

}  // namespace

std::vector<LocatedRange> locateRanges(const std::vector<RawRange>& ranges, const Eigen::Vector3d& x0_ecef,
                                       const GpsTime& t, const OrbitSource* orbits, std::vector<SatId>& missing) {
  std::vector<LocatedRange> located;
  located.reserve(ranges.size());
  std::vector<SatId> without_position;
  for (const RawRange& r : ranges) {
    if (!r.sat_ecef_m) without_position.push_back(r.sat);
  }
  std::vector<VisibleSatellite> visible;
  if (orbits && !without_position.empty()) visible = orbits->locate(without_position, x0_ecef, t);
  for (const RawRange& r : ranges) {
    if (!std::isfinite(r.pr_m)) throw std::invalid_argument("solveLiveFix: pseudorange of " + r.sat.str() + " is not finite");
    if (r.sat_ecef_m) {
      if (!r.sat_ecef_m->allFinite()) throw std::invalid_argument("solveLiveFix: position of " + r.sat.str() + " is not finite");
      located.push_back({r.sat, r.pr_m, *r.sat_ecef_m});
      continue;
    }
    const auto it = std::find_if(visible.begin(), visible.end(), [&](const VisibleSatellite& v) { return v.sat == r.sat; });
    if (it == visible.end()) {
      missing.push_back(r.sat);
      continue;
    }
    located.push_back({r.sat, r.pr_m, it->p_ecef});
  }
  return located;
}

std::vector<LocatedRange> rangesAboveMask(const std::vector<RawRange>& ranges, const Eigen::Vector3d& r_ecef, const GpsTime& t,
                                          const OrbitSource* orbits, double elevation_mask_rad) {
  std::vector<SatId> missing;
  std::vector<LocatedRange> out;
  const maps::Geodetic at = maps::ecefToGeodetic(r_ecef);
  const Eigen::Matrix3d r_enu_ecef = maps::rotationEcefToEnu(at.lat_rad, at.lon_rad);
  for (LocatedRange& l : locateRanges(ranges, r_ecef, t, orbits, missing)) {
    if (maps::lookAngles(r_ecef, r_enu_ecef, l.sat_ecef_m).elevation_rad < elevation_mask_rad) continue;
    out.push_back(std::move(l));
  }
  return out;
}

std::optional<double> meanClockResidual_m(const std::vector<RawRange>& ranges, const Eigen::Vector3d& r_ecef, const GpsTime& t,
                                          const OrbitSource* orbits, const std::vector<SatId>& used) {
  std::vector<SatId> missing;
  double sum = 0.0;
  int count = 0;
  for (const LocatedRange& l : locateRanges(ranges, r_ecef, t, orbits, missing)) {
    if (std::find(used.begin(), used.end(), l.sat) == used.end()) continue;
    sum += l.pr_m - (l.sat_ecef_m - r_ecef).norm();
    ++count;
  }
  if (count == 0) return std::nullopt;
  return sum / count;
}

namespace {

/// The exclusion step on a detection: the method's FDE rows of `lin`; when it names some, the
/// kept ranges converged from lin.x and checked (`lin`, `check` become theirs, `out` records
/// the exclusion). False when the reduced geometry is singular (`out` says so).
bool excludeDetected(const RangesSeenFrom& ranges_from, const std::vector<int>& all, Linearised& lin, GeometryCheck& check,
                     const LiveFixConfig& cfg, LiveFix& out) {
  const std::vector<int> rows = excludedRows(lin, cfg);
  if (rows.empty()) return true;
  Linearised again = converge(ranges_from, keptRanges(lin, rows, out.excluded), lin.x, cfg);
  if (!again.ok) {
    out.note += "the geometry after the exclusion is singular";
    return false;
  }
  lin = std::move(again);
  check = checkAfterExclusion(ranges_from, all, lin, out.excluded, cfg);
  out.fault_excluded = true;
  return true;
}

/// Ranges seen alike from every point (a live epoch's: located once at the reported position).
RangesSeenFrom fixedRanges(const std::vector<LocatedRange>& located) {
  return [&located](const Eigen::Vector3d&) -> const std::vector<LocatedRange>& { return located; };
}

/// The indices of every range seen from x0.
std::vector<int> allRanges(const RangesSeenFrom& ranges_from, const Eigen::Vector3d& x0_ecef) {
  std::vector<int> all(ranges_from(x0_ecef).size());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

/// The note of a singular all-in-view geometry.
std::string tooFewForAPosition(std::size_t ranges) {
  return "too few satellites (" + std::to_string(ranges) + ") or a singular geometry for a position";
}

/// The all-in-view step: every range converged from x0 and checked (`out` gets the detection);
/// false when the geometry is singular (`out` says so).
bool solveAllInView(const RangesSeenFrom& ranges_from, const Eigen::Vector3d& x0_ecef, const LiveFixConfig& cfg,
                    std::vector<int>& all, Linearised& lin, GeometryCheck& check, LiveFix& out) {
  all = allRanges(ranges_from, x0_ecef);
  lin = converge(ranges_from, all, x0_ecef, cfg);
  if (!lin.ok) {
    out.note += tooFewForAPosition(all.size());
    return false;
  }
  check = checkGeometry(lin, cfg);
  out.fault_detected = check.fails;
  return true;
}

}  // namespace

/// A first pass's ranges and its converged all-in-view solution (LiveFix::epoch).
struct LiveEpoch {
  std::vector<LocatedRange> located;
  std::vector<int> all;
  Linearised lin;
  GeometryCheck check;
};

LiveFix solveEpoch(const RangesSeenFrom& ranges_from, const Eigen::Vector3d& x0_ecef, const LiveFixConfig& cfg,
                   bool exclude) {
  LiveFix out;
  std::vector<int> all;
  Linearised lin;
  GeometryCheck check;
  if (!solveAllInView(ranges_from, x0_ecef, cfg, all, lin, check, out)) return out;
  if (exclude && check.fails && !excludeDetected(ranges_from, all, lin, check, cfg, out)) return out;
  fillSolution(lin, check, out);
  return out;
}

namespace {

/// solveEpoch without exclusion over fixed ranges, keeping what excludeFaults() goes on from.
LiveFix firstPass(std::vector<LocatedRange> located, const Eigen::Vector3d& x0_ecef, const LiveFixConfig& cfg) {
  auto epoch = std::make_shared<LiveEpoch>();
  epoch->located = std::move(located);
  const RangesSeenFrom ranges_from = fixedRanges(epoch->located);
  LiveFix out;
  if (!solveAllInView(ranges_from, x0_ecef, cfg, epoch->all, epoch->lin, epoch->check, out)) return out;
  fillSolution(epoch->lin, epoch->check, out);
  out.epoch = std::move(epoch);
  return out;
}

/// The note and list of satellites without an orbit, as solveLiveFix reports them.
void noteMissingOrbits(std::vector<SatId> missing, LiveFix& out) {
  if (!missing.empty()) out.note = std::to_string(missing.size()) + " satellite(s) without an orbit; " + out.note;
  out.missing_orbit = std::move(missing);
}

}  // namespace

LiveFix solveLiveFix(const std::vector<RawRange>& ranges, const maps::Geodetic& initial, const GpsTime& t,
                     const LiveFixConfig& cfg, bool exclude, const OrbitSource* orbits) {
  if (!std::isfinite(initial.lat_rad) || !std::isfinite(initial.lon_rad) || !std::isfinite(initial.h_ell_m)) {
    throw std::invalid_argument("solveLiveFix: the initial position is not finite");
  }
  const Eigen::Vector3d x0 = maps::geodeticToEcef(initial);
  std::vector<SatId> missing;
  std::vector<LocatedRange> located = locateRanges(ranges, x0, t, orbits, missing);
  LiveFix out;
  if (x0.norm() < kMinEarthRadius_m) {
    out.note = "the reported position is not near the Earth's surface";
  } else if (exclude) {
    out = solveEpoch(fixedRanges(located), x0, cfg, true);
  } else {
    out = firstPass(std::move(located), x0, cfg);
  }
  noteMissingOrbits(std::move(missing), out);
  return out;
}

LiveFix excludeFaults(const LiveFix& first, const LiveFixConfig& cfg) {
  if (!first.epoch) throw std::invalid_argument("excludeFaults: the first pass has no all-in-view solution to go on from");
  const LiveEpoch& e = *first.epoch;
  if (!e.check.fails) return first;
  const RangesSeenFrom ranges_from = fixedRanges(e.located);
  LiveFix out;
  out.fault_detected = true;
  Linearised lin = e.lin;
  GeometryCheck check = e.check;
  if (excludeDetected(ranges_from, e.all, lin, check, cfg, out)) fillSolution(lin, check, out);
  noteMissingOrbits(first.missing_orbit, out);
  return out;
}

}  // namespace skylane::integrity
