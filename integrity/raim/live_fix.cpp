#include "integrity/raim/live_fix.hpp"

#include "integrity/araim/fde.hpp"
#include "integrity/gnss/atmosphere.hpp"
#include "integrity/raim/wls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
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
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Geometry g;
  Eigen::VectorXd y;          ///< prefit residuals at x
  std::vector<int> index;     ///< per geometry row: index into the located ranges
};

/// Iterated WLS over `active` (indices into `located`) from x0.
Linearised converge(const std::vector<Located>& located, const std::vector<int>& active, const Eigen::Vector3d& x0,
                    const LiveFixConfig& cfg) {
  Linearised out;
  Eigen::Vector3d x = x0;
  std::array<double, kNumConstellations> clock{};
  bool clocks_set = false;
  for (int it = 0; it < kMaxIterations; ++it) {
    const maps::Geodetic user = maps::ecefToGeodetic(x);
    const double tau = cfg.model.iono_tau_vert_m.value_or(ionoTauVert_m(geomagneticLatitude(user)));
    std::vector<SatLook> looks;
    std::vector<double> ranges;
    std::vector<int> index;
    for (int k : active) {
      const Located& s = located[static_cast<std::size_t>(k)];
      const maps::LookAngles look = maps::lookAngles(x, s.sat_ecef_m);
      if (look.elevation_rad < cfg.elevation_mask_rad) continue;
      looks.push_back({s.sat, look});
      ranges.push_back((s.sat_ecef_m - x).norm());
      index.push_back(k);
    }
    Geometry g = buildGeometry(looks, cfg.model, tau);
    const int n = g.numSats();
    if (n < g.numStates()) return out;
    if (!clocks_set) {  // each receiver clock starts at the mean of its constellation's residuals
      for (Constellation c : g.clocks) {
        double sum = 0.0;
        int count = 0;
        for (int i = 0; i < n; ++i) {
          if (g.sats[static_cast<std::size_t>(i)].constellation != c) continue;
          sum += located[static_cast<std::size_t>(index[static_cast<std::size_t>(i)])].pr_m - ranges[static_cast<std::size_t>(i)];
          ++count;
        }
        clock[static_cast<int>(c)] = sum / count;
      }
      clocks_set = true;
    }
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      const Located& s = located[static_cast<std::size_t>(index[static_cast<std::size_t>(i)])];
      y[i] = s.pr_m - (ranges[static_cast<std::size_t>(i)] + clock[static_cast<int>(s.sat.constellation)]);
    }
    const WlsSolution w = solveWls(g.G, g.sigma_int);
    if (!w.ok) return out;
    const Eigen::VectorXd dx = w.S * y;
    out.ok = true;
    out.x = x;
    out.g = std::move(g);
    out.y = y;
    out.index = index;
    if (dx.head<3>().norm() < kConvergence_m) break;
    const maps::LocalFrame frame(user);
    x = frame.enuToEcef(dx.head<3>());
    for (std::size_t c = 0; c < out.g.clocks.size(); ++c) clock[static_cast<int>(out.g.clocks[c])] += dx[3 + static_cast<Eigen::Index>(c)];
  }
  // The solution is the last linearisation point plus its (small) last step.
  const WlsSolution w = solveWls(out.g.G, out.g.sigma_int);
  const maps::LocalFrame frame(maps::ecefToGeodetic(out.x));
  out.x = frame.enuToEcef((w.S * out.y).head<3>());
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

PlSummary plOf(const Geometry& g, const LiveFixConfig& cfg) {
  return protectionLevels(g, cfg.method, cfg.model, cfg.raim, cfg.araim);
}

}  // namespace

std::vector<LocatedRange> locateRanges(const std::vector<RawRange>& ranges, const Eigen::Vector3d& x0_ecef,
                                       const GpsTime& t, const OrbitSource* orbits, std::vector<SatId>& missing) {
  std::vector<LocatedRange> located;
  located.reserve(ranges.size());
  std::vector<VisibleSatellite> visible;
  bool looked_up = false;
  for (const RawRange& r : ranges) {
    if (!std::isfinite(r.pr_m)) throw std::invalid_argument("solveLiveFix: pseudorange of " + r.sat.str() + " is not finite");
    if (r.sat_ecef_m) {
      if (!r.sat_ecef_m->allFinite()) throw std::invalid_argument("solveLiveFix: position of " + r.sat.str() + " is not finite");
      located.push_back({r.sat, r.pr_m, *r.sat_ecef_m});
      continue;
    }
    if (orbits && !looked_up) {
      visible = orbits->visible(x0_ecef, t, -M_PI / 2.0);  // every satellite above the horizon plane or not
      looked_up = true;
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
  for (LocatedRange& l : locateRanges(ranges, r_ecef, t, orbits, missing)) {
    if (maps::lookAngles(r_ecef, l.sat_ecef_m).elevation_rad < elevation_mask_rad) continue;
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

LiveFix solveLiveFix(const std::vector<RawRange>& ranges, const maps::Geodetic& initial, const GpsTime& t,
                     const LiveFixConfig& cfg, bool exclude, const OrbitSource* orbits) {
  if (!std::isfinite(initial.lat_rad) || !std::isfinite(initial.lon_rad) || !std::isfinite(initial.h_ell_m)) {
    throw std::invalid_argument("solveLiveFix: the initial position is not finite");
  }
  LiveFix out;
  const Eigen::Vector3d x0 = maps::geodeticToEcef(initial);
  const std::vector<Located> located = locateRanges(ranges, x0, t, orbits, out.missing_orbit);
  if (!out.missing_orbit.empty()) out.note += std::to_string(out.missing_orbit.size()) + " satellite(s) without an orbit; ";
  if (x0.norm() < kMinEarthRadius_m) {
    out.note += "the reported position is not near the Earth's surface";
    return out;
  }
  std::vector<int> all(located.size());
  for (std::size_t i = 0; i < located.size(); ++i) all[i] = static_cast<int>(i);
  Linearised lin = converge(located, all, x0, cfg);
  if (!lin.ok) {
    out.note += "too few satellites (" + std::to_string(located.size()) + ") or a singular geometry for a position";
    return out;
  }

  // Detection (and, when asked, exclusion) at the converged all-in-view point.
  std::vector<int> excluded_rows;
  if (cfg.method == IntegrityMethod::kAraim) {
    AraimConfig araim = cfg.araim;
    const AraimFdeResult r = araimFde(lin.g, lin.y, cfg.model, araim);
    out.fault_detected = r.fault_detected;
    if (exclude && r.fault_excluded) excluded_rows = r.excluded;
  } else {
    RaimConfig raim = cfg.raim;
    raim.max_exclusions = exclude ? std::max(1, cfg.raim.max_exclusions) : 0;
    const RaimFdeResult r = raimFde(lin.g, lin.y, raim);
    out.fault_detected = r.fault_detected;
    if (exclude && r.fault_excluded) excluded_rows = r.excluded;
  }

  if (!excluded_rows.empty()) {
    std::vector<int> kept;
    for (std::size_t row = 0; row < lin.index.size(); ++row) {
      if (std::find(excluded_rows.begin(), excluded_rows.end(), static_cast<int>(row)) == excluded_rows.end()) {
        kept.push_back(lin.index[row]);
      } else {
        out.excluded.push_back(located[static_cast<std::size_t>(lin.index[row])].sat);
      }
    }
    Linearised again = converge(located, kept, lin.x, cfg);
    if (!again.ok) {
      out.note += "the geometry after the exclusion is singular";
      return out;
    }
    lin = std::move(again);
    out.fault_excluded = true;
  }
  out.solved = true;
  out.p_ecef = lin.x;
  out.position = maps::ecefToGeodetic(lin.x);
  out.used = lin.g.sats;
  out.pl = plOf(lin.g, cfg);
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
  return out;
}

}  // namespace skylane::integrity
