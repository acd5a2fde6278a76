#include "integrity/raim/spp.hpp"

#include "integrity/araim/fde.hpp"
#include "integrity/gnss/atmosphere.hpp"

#include <Eigen/Cholesky>

#include <cmath>

namespace skylane::integrity {
namespace {

constexpr double kFreqL1_hz = 1575.42e6;
constexpr double kFreqL2_hz = 1227.60e6;
constexpr double kFreqE5a_hz = 1176.45e6;
/// Gauss-Newton stops when the position update is below this [m].
constexpr double kConvergence_m = 1e-4;
constexpr int kMaxIterations = 12;
/// Before this the receiver is too far from the Earth's surface for look angles to mean anything.
constexpr double kMinEarthRadius_m = 6.0e6;

struct Measurement {
  SatId sat;
  double pr_m = 0.0;
  bool iono_free = false;
  const BroadcastEphemeris* eph = nullptr;
  Eigen::Vector3d p_sat_tx = Eigen::Vector3d::Zero();  ///< at transmit time, ECEF of transmit instant
  double sat_clock_m = 0.0;                            ///< c·dt_sv incl. group delay when single frequency
};

bool valid(double v) { return std::isfinite(v) && v > 1e6; }

/// Picks code observations: band 1 and the second band of each system.
std::vector<Measurement> collect(const ObservationEpoch& ep, const ObservationData& obs, const NavigationData& nav,
                                 const SppConfig& cfg, std::string& note) {
  std::vector<Measurement> out;
  int no_eph = 0;
  for (const SatObservation& so : ep.sats) {
    const Constellation c = so.sat.constellation;
    if (c != Constellation::kGps && !(c == Constellation::kGalileo && cfg.use_galileo)) continue;
    const auto& types = obs.types[static_cast<int>(c)];
    const bool gps = c == Constellation::kGps;
    const int i1 = findObsType(types, 'C', 1, gps ? "CWPXSLYM" : "CXBAZ");
    const int i2 = gps ? findObsType(types, 'C', 2, "WPXLSCYM") : findObsType(types, 'C', 5, "QXI");
    const double p1 = i1 >= 0 ? so.values[static_cast<std::size_t>(i1)] : NAN;
    const double p2 = i2 >= 0 ? so.values[static_cast<std::size_t>(i2)] : NAN;
    Measurement m;
    m.sat = so.sat;
    const double f1 = kFreqL1_hz, f2 = gps ? kFreqL2_hz : kFreqE5a_hz;
    const bool have2 = valid(p1) && valid(p2);
    if (cfg.iono == IonoMode::kIonoFree && !have2) continue;
    if (cfg.iono != IonoMode::kKlobuchar && have2) {
      m.pr_m = (f1 * f1 * p1 - f2 * f2 * p2) / (f1 * f1 - f2 * f2);
      m.iono_free = true;
    } else if (valid(p1)) {
      m.pr_m = p1;
    } else {
      continue;
    }
    const auto inj = cfg.injected_bias_m.find(so.sat);
    if (inj != cfg.injected_bias_m.end()) m.pr_m += inj->second;
    m.eph = selectEphemeris(nav, so.sat, ep.t);
    if (!m.eph) { ++no_eph; continue; }
    // Transmit time in satellite time, then correct for the satellite clock (two passes).
    GpsTime t_tx = ep.t.plus(-m.pr_m / kSpeedOfLight_mps);
    SatelliteState st = satelliteState(*m.eph, t_tx);
    t_tx = t_tx.plus(-st.clock_s);
    st = satelliteState(*m.eph, t_tx);
    m.p_sat_tx = st.p_ecef;
    double dts = st.clock_s;
    if (!m.iono_free) dts -= m.eph->sat.constellation == Constellation::kGalileo ? m.eph->bgd_e5b_s : m.eph->tgd_s;
    m.sat_clock_m = kSpeedOfLight_mps * dts;
    out.push_back(m);
  }
  if (no_eph > 0) note += std::to_string(no_eph) + " satellite(s) without a valid ephemeris; ";
  return out;
}

/// Receiver clock per constellation [m].
using Clocks = std::array<double, kNumConstellations>;

/// One FDE solution at a linearisation point, RAIM or ARAIM alike.
struct FdeOutcome {
  bool ok = false;
  Eigen::VectorXd dx;
  Geometry final_geometry;
  std::vector<int> excluded;
  bool fault_detected = false;
  double statistic = 0, threshold = 0;
  PlSummary pl;
};

/// The solver's state through the iterations.
struct SppState {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  ///< receiver, ECEF [m]
  Clocks clock{};
  FdeOutcome fde;
  std::vector<const Measurement*> in_view;  ///< the measurements of the last geometry, in its order
};

/// The prefit residuals and look angles of the measurements above the mask at the state's point.
struct Prefit {
  std::vector<SatLook> looks;
  std::vector<double> residuals_m;
  bool any_single = false;  ///< a single-frequency measurement is among them
};

/// Phase A: unweighted, no atmosphere, no mask — brings any start point to the Earth's surface.
void findInitialPosition(const std::vector<Measurement>& meas, SppState& s) {
  Eigen::Vector3d& x = s.x;
  Clocks& clock = s.clock;
  for (int it = 0; it < kMaxIterations; ++it) {
    const int n = static_cast<int>(meas.size());
    if (n < 4) break;
    Eigen::MatrixXd G(n, 4);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      const Measurement& m = meas[static_cast<std::size_t>(i)];
      const Eigen::Vector3d p = earthRotationCorrection(m.p_sat_tx, (m.p_sat_tx - x).norm() / kSpeedOfLight_mps);
      const Eigen::Vector3d d = p - x;
      const double rho = d.norm();
      G.block<1, 3>(i, 0) = -(d / rho).transpose();
      G(i, 3) = 1.0;
      y[i] = m.pr_m - (rho + clock[0] - m.sat_clock_m);
    }
    const Eigen::Vector4d dx = (G.transpose() * G).ldlt().solve(G.transpose() * y);
    if (!dx.allFinite()) break;
    x += dx.head<3>();
    clock[0] += dx[3];
    if (dx.head<3>().norm() < 1.0) break;
  }
  for (double& c : clock) c = clock[0];
}

/// Prefit residuals with the atmosphere, for the measurements above the mask; the state's
/// in_view lists them.
Prefit prefitResiduals(const std::vector<Measurement>& meas, const maps::Geodetic& user, const NavigationData& nav,
                       const SppConfig& cfg, const GpsTime& t, SppState& s) {
  Prefit out;
  s.in_view.clear();
  for (const Measurement& m : meas) {
    const Eigen::Vector3d p = earthRotationCorrection(m.p_sat_tx, (m.p_sat_tx - s.x).norm() / kSpeedOfLight_mps);
    const maps::LookAngles look = maps::lookAngles(s.x, p);
    if (look.elevation_rad < cfg.elevation_mask_rad) continue;
    double iono = 0.0;
    if (!m.iono_free) {
      out.any_single = true;
      // Galileo E1 shares L1's frequency; the GPS model stands in for NeQuick G here.
      if (nav.klobuchar) iono = klobucharDelay_m(*nav.klobuchar, user, look, t);
    }
    const double tropo = saastamoinenDelay_m(user, look.elevation_rad);
    const double rho = (p - s.x).norm();
    out.residuals_m.push_back(m.pr_m - (rho + s.clock[static_cast<int>(m.sat.constellation)] - m.sat_clock_m + iono + tropo));
    out.looks.push_back({m.sat, look});
    s.in_view.push_back(&m);
  }
  return out;
}

/// FDE of the configured method (RAIM or ARAIM) on one linearisation.
FdeOutcome runFde(const Geometry& g, const Eigen::VectorXd& y, const SppConfig& cfg) {
  if (cfg.method == IntegrityMethod::kAraim) {
    ErrorModel araim_model = cfg.model;  // the ISM priors; σ's come from `g`
    const AraimFdeResult r = araimFde(g, y, araim_model, cfg.araim);
    return {r.solution_ok, r.dx, r.final_geometry, r.excluded, r.fault_detected, r.max_test_ratio, 1.0, summarize(r.pl)};
  }
  const RaimFdeResult r = raimFde(g, y, cfg.raim);
  FdeOutcome fde{r.solution_ok, r.dx, r.final_geometry, r.excluded, r.fault_detected, r.test_statistic, r.threshold,
                 summarize(r.pl, cfg.araim.requirements)};
  if (r.fault_detected && !r.fault_excluded) fde.pl.reason = r.pl.reason;
  return fde;
}

/// Moves the state by the FDE solution's update (ENU at `user`); returns the position step [m].
double applyUpdate(const maps::Geodetic& user, SppState& s) {
  const maps::LocalFrame frame(user);
  const Eigen::Vector3d dx_ecef = frame.enuToEcef(s.fde.dx.head<3>()) - s.x;
  s.x += dx_ecef;
  for (std::size_t k = 0; k < s.fde.final_geometry.clocks.size(); ++k) {
    s.clock[static_cast<int>(s.fde.final_geometry.clocks[k])] += s.fde.dx[3 + static_cast<int>(k)];
  }
  return dx_ecef.norm();
}

/// Phase B: weighted, corrected, masked, with FDE at each linearisation point; false (with the
/// reason in the note) when FDE finds no solution.
bool solveWeighted(const ObservationEpoch& ep, const std::vector<Measurement>& meas, const NavigationData& nav,
                   const SppConfig& cfg, SppState& s, SppEpoch& out) {
  for (int it = 0; it < kMaxIterations; ++it) {
    const maps::Geodetic user = maps::ecefToGeodetic(s.x);
    const double tau = cfg.model.iono_tau_vert_m.value_or(ionoTauVert_m(geomagneticLatitude(user)));
    const Prefit pre = prefitResiduals(meas, user, nav, cfg, ep.t, s);
    ErrorModel model = cfg.model;
    model.setUserModel(pre.any_single ? UserErrorModel::kSingleFrequency : UserErrorModel::kDualFrequency);
    const Geometry g = buildGeometry(pre.looks, model, tau);
    const Eigen::VectorXd y =
        Eigen::Map<const Eigen::VectorXd>(pre.residuals_m.data(), static_cast<Eigen::Index>(pre.residuals_m.size()));
    s.fde = runFde(g, y, cfg);
    if (!s.fde.ok) {
      out.note += s.fde.pl.reason;
      return false;
    }
    const double step_m = applyUpdate(user, s);
    out.iono_free = !pre.any_single;
    if (step_m < kConvergence_m) break;
  }
  return true;
}

/// The solved epoch: position, clock, satellites used and excluded, and the FDE's verdict.
void fillSolution(const SppState& s, SppEpoch& out) {
  out.solved = true;
  out.p_ecef = s.x;
  out.position = maps::ecefToGeodetic(s.x);
  out.clock_m = s.fde.final_geometry.clocks.empty() ? 0.0 : s.clock[static_cast<int>(s.fde.final_geometry.clocks[0])];
  out.used = s.fde.final_geometry.sats;
  for (int idx : s.fde.excluded) out.excluded.push_back(s.in_view[static_cast<std::size_t>(idx)]->sat);
  out.fault_detected = s.fde.fault_detected;
  out.test_statistic = s.fde.statistic;
  out.threshold = s.fde.threshold;
  out.pl = s.fde.pl;
  if (!out.pl.pl_computed) out.note += out.pl.reason;
}

}  // namespace

SppEpoch solveSppEpoch(const ObservationEpoch& ep, const ObservationData& obs, const NavigationData& nav,
                       const SppConfig& cfg, const std::optional<Eigen::Vector3d>& initial_ecef) {
  SppEpoch out;
  out.t = ep.t;
  out.source_line = ep.source_line;
  const std::vector<Measurement> meas = collect(ep, obs, nav, cfg, out.note);
  SppState s;
  s.x = initial_ecef.value_or(Eigen::Vector3d::Zero());
  if (s.x.norm() < kMinEarthRadius_m) findInitialPosition(meas, s);
  if (s.x.norm() < kMinEarthRadius_m) {
    out.note += "no initial position could be found (" + std::to_string(meas.size()) + " satellites)";
    return out;
  }
  if (!solveWeighted(ep, meas, nav, cfg, s, out)) return out;
  fillSolution(s, out);
  return out;
}

std::vector<SppEpoch> solveSpp(const ObservationData& obs, const NavigationData& nav, const SppConfig& cfg,
                               const std::function<void(std::size_t, std::size_t)>& progress) {
  std::vector<SppEpoch> out;
  out.reserve(obs.epochs.size());
  std::optional<Eigen::Vector3d> prior = obs.approx_position_ecef;
  if (prior && prior->norm() < kMinEarthRadius_m) prior.reset();
  for (std::size_t i = 0; i < obs.epochs.size(); ++i) {
    out.push_back(solveSppEpoch(obs.epochs[i], obs, nav, cfg, prior));
    if (out.back().solved) prior = out.back().p_ecef;
    if (progress && (i % 64 == 0 || i + 1 == obs.epochs.size())) progress(i + 1, obs.epochs.size());
  }
  return out;
}

}  // namespace skylane::integrity
