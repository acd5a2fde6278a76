#include "integrity/raim/spp.hpp"

#include "integrity/gnss/atmosphere.hpp"
#include "integrity/raim/live_fix.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace skylane::integrity {
namespace {

constexpr double kFreqL1_hz = 1575.42e6;
constexpr double kFreqL2_hz = 1227.60e6;
constexpr double kFreqE5a_hz = 1176.45e6;
/// Iterations of the initial-position search (phase A) at most.
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

/// Phase A: unweighted, no atmosphere, no mask — brings any start point to the Earth's surface.
void findInitialPosition(const std::vector<Measurement>& meas, Eigen::Vector3d& x) {
  double clock = 0.0;
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
      y[i] = m.pr_m - (rho + clock - m.sat_clock_m);
    }
    const Eigen::Vector4d dx = (G.transpose() * G).ldlt().solve(G.transpose() * y);
    if (!dx.allFinite()) break;
    x += dx.head<3>();
    clock += dx[3];
    if (dx.head<3>().norm() < 1.0) break;
  }
}

/// The measurements as the epoch solver sees them from a point: each satellite rotated into the
/// reception frame (Sagnac, over the flight time from that point) and, above the mask, its
/// pseudorange corrected for the satellite clock, the broadcast ionosphere (single frequency) and
/// the troposphere at that point.
class CorrectedRanges {
 public:
  CorrectedRanges(const std::vector<Measurement>& meas, const NavigationData& nav, const SppConfig& cfg, const GpsTime& t)
      : meas_(meas), nav_(nav), mask_rad_(cfg.elevation_mask_rad), t_(t) {}

  const std::vector<LocatedRange>& from(const Eigen::Vector3d& x) {
    const maps::Geodetic user = maps::ecefToGeodetic(x);
    const Eigen::Matrix3d r_enu_ecef = maps::rotationEcefToEnu(user.lat_rad, user.lon_rad);
    ranges_.clear();
    for (const Measurement& m : meas_) {
      const Eigen::Vector3d p = earthRotationCorrection(m.p_sat_tx, (m.p_sat_tx - x).norm() / kSpeedOfLight_mps);
      const maps::LookAngles look = maps::lookAngles(x, r_enu_ecef, p);
      double pr = m.pr_m + m.sat_clock_m;
      if (look.elevation_rad >= mask_rad_) {
        // Galileo E1 shares L1's frequency; the GPS model stands in for NeQuick G here.
        if (!m.iono_free && nav_.klobuchar) pr -= klobucharDelay_m(*nav_.klobuchar, user, look, t_);
        pr -= saastamoinenDelay_m(user, look.elevation_rad);
      }
      ranges_.push_back({m.sat, pr, p});
    }
    return ranges_;
  }

  /// Whether a single-frequency measurement is above the mask at x.
  bool anySingleFrequencyAbove(const Eigen::Vector3d& x) const {
    const maps::Geodetic user = maps::ecefToGeodetic(x);
    const Eigen::Matrix3d r_enu_ecef = maps::rotationEcefToEnu(user.lat_rad, user.lon_rad);
    return std::any_of(meas_.begin(), meas_.end(), [&](const Measurement& m) {
      const Eigen::Vector3d p = earthRotationCorrection(m.p_sat_tx, (m.p_sat_tx - x).norm() / kSpeedOfLight_mps);
      return !m.iono_free && maps::lookAngles(x, r_enu_ecef, p).elevation_rad >= mask_rad_;
    });
  }

 private:
  const std::vector<Measurement>& meas_;
  const NavigationData& nav_;
  double mask_rad_;
  GpsTime t_;
  std::vector<LocatedRange> ranges_;
};

/// The epoch solver's settings for SPP: the airborne error model of the frequencies in view.
LiveFixConfig epochConfig(const SppConfig& cfg, bool single_frequency) {
  LiveFixConfig out;
  out.method = cfg.method;
  out.model = cfg.model;
  out.model.setUserModel(single_frequency ? UserErrorModel::kSingleFrequency : UserErrorModel::kDualFrequency);
  out.raim = cfg.raim;
  out.araim = cfg.araim;
  out.elevation_mask_rad = cfg.elevation_mask_rad;
  return out;
}

/// The solved epoch: position, clock, satellites used and excluded, and the test's verdict.
void fillSolution(const LiveFix& f, const std::vector<Measurement>& meas, SppEpoch& out) {
  out.solved = f.solved;
  out.note += f.note;
  if (!f.solved) return;
  out.p_ecef = f.p_ecef;
  out.position = f.position;
  out.clock_m = f.clock_m;
  out.used = f.used;
  out.excluded = f.excluded;
  out.iono_free = std::none_of(meas.begin(), meas.end(), [&](const Measurement& m) {
    return !m.iono_free && std::find(f.used.begin(), f.used.end(), m.sat) != f.used.end();
  });
  out.fault_detected = f.fault_detected;
  out.test_statistic = f.test_statistic;
  out.threshold = f.threshold;
  out.pl = f.pl;
  if (!out.pl.pl_computed && !out.pl.reason.empty()) out.note += out.pl.reason;
}

}  // namespace

SppEpoch solveSppEpoch(const ObservationEpoch& ep, const ObservationData& obs, const NavigationData& nav,
                       const SppConfig& cfg, const std::optional<Eigen::Vector3d>& initial_ecef) {
  SppEpoch out;
  out.t = ep.t;
  out.source_line = ep.source_line;
  const std::vector<Measurement> meas = collect(ep, obs, nav, cfg, out.note);
  Eigen::Vector3d x = initial_ecef.value_or(Eigen::Vector3d::Zero());
  if (x.norm() < kMinEarthRadius_m) findInitialPosition(meas, x);
  if (x.norm() < kMinEarthRadius_m) {
    out.note += "no initial position could be found (" + std::to_string(meas.size()) + " satellites)";
    return out;
  }
  CorrectedRanges ranges(meas, nav, cfg, ep.t);
  const LiveFixConfig epoch_cfg = epochConfig(cfg, ranges.anySingleFrequencyAbove(x));
  const LiveFix f = solveEpoch([&ranges](const Eigen::Vector3d& at) -> const std::vector<LocatedRange>& { return ranges.from(at); },
                               x, epoch_cfg, true);
  fillSolution(f, meas, out);
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
