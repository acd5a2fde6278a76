#include "integrity/sim/run.hpp"


#include "maps/parse_error.hpp"
#include "maps/text_file.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>

namespace skylane::integrity::sim {

std::string_view methodName(Method m) {
  switch (m) {
    case Method::kFaultMode: return "fault_mode";
    case Method::kThreeHypothesisIns: return "three_hypothesis_ins";
    case Method::kRaim: return "raim";
    case Method::kAraim: return "araim";
  }
  return "?";
}

OrbitSource loadOrbits(const Scenario& s) { return loadOrbitFiles(s.orbit_files, s.source, "$.orbits"); }

namespace {

MethodSample sampleOf(bool available, const Eigen::Vector3d& r_ecef, const Eigen::Vector3d& truth_ecef,
                      const Eigen::Matrix3d& R_enu_ecef, double hpl, double vpl) {
  MethodSample m;
  m.available = available;
  const Eigen::Vector3d e = R_enu_ecef * (r_ecef - truth_ecef);
  m.hpe_m = std::hypot(e.x(), e.y());
  m.vpe_m = std::abs(e.z());
  m.hpl_m = hpl;
  m.vpl_m = vpl;
  return m;
}

/// \brief The navigator, started from the truth perturbed within its filter's initial
/// covariance (an initial alignment and fix), drawn from its own stream so that the sensors'
/// draws do not shift.
ins::Navigator alignedNavigator(const ins::NavigatorConfig& cfg, const SensorSimulator& sim, std::uint64_t seed) {
  std::mt19937_64 init_rng(seed ^ 0x9E3779B97F4A7C15ULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  const ins::EkfConfig& ec = cfg.ekf;
  ins::NavState start = sim.truthNav();
  for (int i = 0; i < 3; ++i) {
    start.r_ecef_m[i] += ec.initial_position_m * n01(init_rng);
    start.v_ecef_mps[i] += ec.initial_velocity_mps * n01(init_rng);
  }
  const Eigen::Vector3d tilt(ec.initial_attitude_rad * n01(init_rng), ec.initial_attitude_rad * n01(init_rng),
                             ec.initial_attitude_rad * n01(init_rng));
  start.C_ecef_body = ins::expSo3(tilt) * start.C_ecef_body;
  return ins::Navigator(cfg, start, sim.clockBias_m() + ec.initial_clock_m * n01(init_rng), 0.0);
}

/// \brief Each method's availability, position error against the truth (local ENU at the
/// truth, rotation `R`) and protection levels.
void scoreMethods(const ins::NavigatorEpoch& ep, const Eigen::Vector3d& truth_ecef, const Eigen::Matrix3d& R,
                  EpochRecord& r) {
  const bool usable = !ep.outage;
  r.methods[static_cast<int>(Method::kFaultMode)] =
      sampleOf(usable && ep.fault_mode_available, ep.r_ecef_m, truth_ecef, R, ep.fault_mode_hpl_m, ep.fault_mode_vpl_m);
  // The patent (US 10,466,362) names no IMU fault detector; the three-hypothesis INS PL runs inside the fault-mode flow (LSR FDE,
  // innovation test, GNSS alone with RAIM when the IMU is declared faulty), so that the two
  // differ only in their protection-level formulas.
  r.methods[static_cast<int>(Method::kThreeHypothesisIns)] =
      ep.degraded ? sampleOf(usable && ep.raim.available, ep.raim.r_ecef_m, truth_ecef, R, ep.raim.hpl_m,
                             ep.raim.vpl_m)
                  : sampleOf(usable && ep.three_hypothesis_ins.available, ep.ekf_r_ecef_m, truth_ecef, R, ep.three_hypothesis_ins.hpl_m,
                             ep.three_hypothesis_ins.vpl_m);
  r.methods[static_cast<int>(Method::kRaim)] =
      sampleOf(usable && ep.raim.available, ep.raim.r_ecef_m, truth_ecef, R, ep.raim.hpl_m, ep.raim.vpl_m);
  r.methods[static_cast<int>(Method::kAraim)] =
      sampleOf(usable && ep.araim.available, ep.araim.r_ecef_m, truth_ecef, R, ep.araim.hpl_m, ep.araim.vpl_m);
}

/// \brief The monitor's side of the epoch: the fault-mode PLs (FF, GS, I, GSI), the satellites
/// seen, used and excluded, and the GNSS and IMU tests.
void recordMonitor(const ins::NavigatorEpoch& ep, EpochRecord& r) {
  const InsFaultMode modes[4] = {InsFaultMode::kFaultFree, InsFaultMode::kGnssSingle, InsFaultMode::kImu,
                                 InsFaultMode::kGnssSingleImu};
  for (int i = 0; i < 4; ++i) {
    r.mode_hpl_m[i] = ep.fault_modes.modes[static_cast<int>(modes[i])].hpl_m;
    r.mode_vpl_m[i] = ep.fault_modes.modes[static_cast<int>(modes[i])].vpl_m;
  }
  r.outage = ep.outage;
  r.visible = ep.visible;
  r.used = ep.used;
  r.excluded = ep.excluded;
  r.gnss_fault_detected = ep.gnss_fault_detected;
  r.imu_statistic = ep.imu_statistic;
  r.imu_threshold = ep.imu_threshold;
  r.imu_fault_detected = ep.imu_fault_detected;
  r.degraded = ep.degraded;
}

/// \brief One GNSS epoch of the navigator scored against the truth.
EpochRecord scoreEpoch(const ins::NavigatorEpoch& ep, const TruthState& truth, const Trajectory& trajectory,
                       double t_s) {
  const Eigen::Matrix3d R = maps::rotationEcefToEnu(truth.geodetic.lat_rad, truth.geodetic.lon_rad);
  EpochRecord r;
  r.t_s = t_s;
  r.truth_enu_m = truth.p_enu_m;
  r.estimate_enu_m = trajectory.frame().ecefToEnu(ep.r_ecef_m);
  r.error_enu_m = R * (ep.r_ecef_m - truth.p_ecef_m);
  scoreMethods(ep, truth.p_ecef_m, R, r);
  recordMonitor(ep, r);
  return r;
}

/// \brief Whether a satellite fault moved a range of this epoch, and whether an IMU fault is on.
void markActiveFaults(const std::vector<FaultSpec>& faults, const GnssEpoch& g, EpochRecord& r) {
  for (const FaultSpec& f : faults) {
    if (f.valueAt(g.t_s) == 0.0) continue;
    if (f.target == FaultTarget::kSatellite) {
      for (const Pseudorange& p : g.ranges) r.satellite_fault_active = r.satellite_fault_active || p.injected_m != 0.0;
    }
    if (f.target == FaultTarget::kAccelerometer || f.target == FaultTarget::kGyro) r.imu_fault_active = true;
  }
}

}  // namespace

RunResult runScenario(const Scenario& s, const OrbitSource& orbits, std::uint64_t seed) {
  const Trajectory trajectory(s.origin, s.waypoints, s.turn_radius_m);
  SensorSimulator sim(trajectory, orbits, s.start, s.sensors, s.faults, seed);
  ins::Navigator nav = alignedNavigator(s.navigator, sim, seed);

  RunResult out;
  out.duration_s = trajectory.duration_s();
  out.epochs.reserve(static_cast<std::size_t>(out.duration_s * s.sensors.gnss_rate_hz) + 2);
  std::vector<ins::PseudorangeInput> ranges;
  while (sim.running()) {
    const ImuSample imu = sim.stepImu();
    ++out.imu_steps;
    nav.propagate(imu.dtheta_rad, imu.dv_mps, imu.dt_s);
    if (!sim.gnssDue()) continue;
    const GnssEpoch g = sim.gnss();
    const AidingSample aid = sim.aiding();
    ranges.clear();
    for (const Pseudorange& p : g.ranges) ranges.push_back({p.sat, p.sat_ecef_m, p.pseudorange_m});
    const ins::NavigatorEpoch ep = nav.epoch(g.t_s, ranges, aid.baro_h_m, aid.heading_rad);
    EpochRecord r = scoreEpoch(ep, sim.truth(), trajectory, g.t_s);
    markActiveFaults(s.faults, g, r);
    out.epochs.push_back(std::move(r));
  }
  return out;
}

void writeCsv(std::ostream& os, const RunResult& run) {
  os << "t_s,truth_e_m,truth_n_m,truth_u_m,est_e_m,est_n_m,est_u_m,err_e_m,err_n_m,err_u_m";
  for (int m = 0; m < kNumMethods; ++m) {
    const std::string n(methodName(static_cast<Method>(m)));
    os << ',' << n << "_available," << n << "_hpe_m," << n << "_vpe_m," << n << "_hpl_m," << n << "_vpl_m";
  }
  os << ",ff_hpl_m,gs_hpl_m,i_hpl_m,gsi_hpl_m,ff_vpl_m,gs_vpl_m,i_vpl_m,gsi_vpl_m"
        ",outage,visible,used,excluded,gnss_fault_detected,imu_statistic,imu_threshold,imu_fault_detected,degraded,"
        "satellite_fault_active,imu_fault_active\n";
  os << std::fixed << std::setprecision(3);
  for (const EpochRecord& r : run.epochs) {
    os << r.t_s;
    for (const Eigen::Vector3d* v : {&r.truth_enu_m, &r.estimate_enu_m, &r.error_enu_m}) {
      os << ',' << v->x() << ',' << v->y() << ',' << v->z();
    }
    for (const MethodSample& m : r.methods) {
      os << ',' << (m.available ? 1 : 0) << ',' << m.hpe_m << ',' << m.vpe_m << ',' << m.hpl_m << ',' << m.vpl_m;
    }
    for (double v : r.mode_hpl_m) os << ',' << v;
    for (double v : r.mode_vpl_m) os << ',' << v;
    os << ',' << r.outage << ',' << r.visible << ',' << r.used << ',';
    for (std::size_t i = 0; i < r.excluded.size(); ++i) os << (i ? " " : "") << r.excluded[i].str();
    os << ',' << r.gnss_fault_detected << ',' << r.imu_statistic << ',' << r.imu_threshold << ','
       << r.imu_fault_detected << ',' << r.degraded << ',' << r.satellite_fault_active << ',' << r.imu_fault_active
       << '\n';
  }
}

StanfordHistogram::StanfordHistogram(double alert_limit_m_, double max_m_, int bins_)
    : alert_limit_m(alert_limit_m_), max_m(max_m_), bins(bins_),
      counts(static_cast<std::size_t>(bins_) * static_cast<std::size_t>(bins_), 0) {}

void StanfordHistogram::add(double error_m, double pl_m, bool available) {
  ++total;
  if (!available) {
    ++no_pl;
    return;
  }
  if (error_m > pl_m) ++misleading;
  if (pl_m > alert_limit_m) {
    ++unavailable;
    if (error_m > pl_m) ++unavailable_mi;
  } else if (error_m > alert_limit_m) {
    ++hmi;
  } else if (error_m > pl_m) {
    ++mi;
  } else {
    ++normal;
  }
  if (bins <= 0) return;
  auto bin = [this](double v) {
    const int b = static_cast<int>(v / max_m * bins);
    return std::clamp(b, 0, bins - 1);
  };
  ++counts[static_cast<std::size_t>(bin(pl_m)) * static_cast<std::size_t>(bins) + static_cast<std::size_t>(bin(error_m))];
}

void StanfordHistogram::merge(const StanfordHistogram& o) {
  if (o.bins != bins || o.counts.size() != counts.size()) throw std::invalid_argument("stanford: histogram shapes differ");
  for (std::size_t i = 0; i < counts.size(); ++i) counts[i] += o.counts[i];
  total += o.total;
  normal += o.normal;
  mi += o.mi;
  hmi += o.hmi;
  unavailable += o.unavailable;
  unavailable_mi += o.unavailable_mi;
  no_pl += o.no_pl;
  misleading += o.misleading;
}

MonteCarloResult emptyMonteCarlo(const Scenario& s) {
  MonteCarloResult r;
  for (MethodStats& m : r.methods) {
    m.horizontal = StanfordHistogram(s.hal_m, 2.0 * s.hal_m, 100);
    m.vertical = StanfordHistogram(s.val_m, 2.0 * s.val_m, 100);
  }
  return r;
}

void accumulate(const RunResult& run, MonteCarloResult& into) {
  ++into.runs;
  for (const EpochRecord& e : run.epochs) {
    ++into.epochs;
    if (e.satellite_fault_active || e.imu_fault_active) ++into.faulted_epochs;
    for (int m = 0; m < kNumMethods; ++m) {
      const MethodSample& s = e.methods[m];
      into.methods[m].horizontal.add(s.hpe_m, s.hpl_m, s.available);
      into.methods[m].vertical.add(s.vpe_m, s.vpl_m, s.available);
    }
  }
}

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

}  // namespace

Scenario monteCarloVariant(const Scenario& base, std::uint64_t run_index) {
  // Variations (all uniform unless said):
  //   start: base start + [0, 24 h)  (a new satellite geometry every run)
  //   flight: lawnmower, 2–6 lines of 300–1000 m, 60–200 m apart, 20–120 m up, 5–15 m/s, any heading
  //   fault, one of (probabilities): none (0.15); satellite step 3–12 σ (0.25, the LSR detects
  //   ~5–7 σ); satellite ramp 0.02–0.5 m/s (0.10); accelerometer step 0.005–0.1 m/s² on a random
  //   axis (0.15); accelerometer ramp 2e-4–5e-3 m/s³ (0.10); gyro step 2e-3–3e-2 rad/s (0.10);
  //   satellite step and accelerometer step together (0.10, the GSI fault mode); GNSS outage of
  //   10–60 s (0.05). Windows start in [60 s, T − 90 s] and last 30–200 s.
  //   The faulted satellite is picked when the fault starts (FaultSpec::sats empty = "one of the
  //   satellites in view, chosen by `pick`").
  std::mt19937_64 rng(splitmix64(base.seed * 0x100000001B3ULL + run_index));
  auto uni = [&rng](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  Scenario s = base;
  s.seed = splitmix64(base.seed ^ (run_index + 1));
  s.start = base.start.plus(std::floor(uni(0.0, 86400.0)));
  const int lines = static_cast<int>(uni(2.0, 7.0));
  s.waypoints = lawnmower(lines, uni(300.0, 1000.0), uni(60.0, 200.0), uni(20.0, 120.0), uni(5.0, 15.0),
                          uni(0.0, 2.0 * M_PI));
  s.turn_radius_m = 30.0;
  const double T = Trajectory(s.origin, s.waypoints, s.turn_radius_m).duration_s();
  s.faults.clear();
  auto window = [&](FaultSpec& f) {
    f.t_start_s = uni(60.0, std::max(61.0, T - 90.0));
    f.t_end_s = f.t_start_s + uni(30.0, 200.0);
  };
  auto satFault = [&](bool ramp) {
    FaultSpec f;
    f.target = FaultTarget::kSatellite;
    f.ramp = ramp;
    f.in_sigma = !ramp;
    f.magnitude = ramp ? uni(0.02, 0.5) : uni(3.0, 12.0);
    f.pick = uni(0.0, 1.0);
    window(f);
    return f;
  };
  auto imuFault = [&](FaultTarget target, bool ramp) {
    FaultSpec f;
    f.target = target;
    f.ramp = ramp;
    f.axis = static_cast<int>(uni(0.0, 3.0));
    if (target == FaultTarget::kGyro) {
      f.magnitude = uni(2e-3, 3e-2);
    } else {
      f.magnitude = ramp ? uni(2e-4, 5e-3) : uni(0.005, 0.1);
    }
    if (uni(0.0, 1.0) < 0.5) f.magnitude = -f.magnitude;
    window(f);
    return f;
  };
  const double u = uni(0.0, 1.0);
  if (u < 0.15) {
  } else if (u < 0.40) {
    s.faults.push_back(satFault(false));
  } else if (u < 0.50) {
    s.faults.push_back(satFault(true));
  } else if (u < 0.65) {
    s.faults.push_back(imuFault(FaultTarget::kAccelerometer, false));
  } else if (u < 0.75) {
    s.faults.push_back(imuFault(FaultTarget::kAccelerometer, true));
  } else if (u < 0.85) {
    s.faults.push_back(imuFault(FaultTarget::kGyro, false));
  } else if (u < 0.95) {
    FaultSpec a = imuFault(FaultTarget::kAccelerometer, false);
    FaultSpec g = satFault(false);
    g.t_start_s = a.t_start_s;
    g.t_end_s = a.t_end_s;
    s.faults.push_back(a);
    s.faults.push_back(g);
  } else {
    FaultSpec f;
    f.target = FaultTarget::kGnssOutage;
    f.magnitude = 1.0;
    f.t_start_s = uni(60.0, std::max(61.0, T - 90.0));
    f.t_end_s = f.t_start_s + uni(10.0, 60.0);
    s.faults.push_back(f);
  }
  return s;
}

MonteCarloResult monteCarlo(const Scenario& base, const OrbitSource& orbits, std::uint64_t runs, int threads,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  threads = std::max(1, threads);
  std::atomic<std::uint64_t> next{0};
  std::atomic<std::uint64_t> done{0};
  std::mutex mutex;
  MonteCarloResult total = emptyMonteCarlo(base);
  std::exception_ptr failure;
  auto worker = [&]() {
    MonteCarloResult mine = emptyMonteCarlo(base);
    try {
      for (std::uint64_t i = next++; i < runs; i = next++) {
        const Scenario v = monteCarloVariant(base, i);
        accumulate(runScenario(v, orbits, v.seed), mine);
        const std::uint64_t d = ++done;
        if (progress) {
          const std::lock_guard<std::mutex> lock(mutex);
          progress(d, runs);
        }
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      next = runs;
    }
    const std::lock_guard<std::mutex> lock(mutex);
    for (int m = 0; m < kNumMethods; ++m) {
      total.methods[m].horizontal.merge(mine.methods[m].horizontal);
      total.methods[m].vertical.merge(mine.methods[m].vertical);
    }
    total.runs += mine.runs;
    total.epochs += mine.epochs;
    total.faulted_epochs += mine.faulted_epochs;
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  return total;
}

double upperBound95(std::uint64_t k, std::uint64_t n) {
  if (n == 0) return 1.0;
  const double dn = static_cast<double>(n);
  if (k == 0) return 1.0 - std::pow(0.05, 1.0 / dn);
  if (k >= n) return 1.0;
  // Clopper–Pearson: the p with P(X ≤ k | n, p) = 0.05, by bisection on the binomial CDF.
  auto cdf = [&](double p) {
    double sum = 0.0;
    for (std::uint64_t j = 0; j <= k; ++j) {
      const double dj = static_cast<double>(j);
      sum += std::exp(std::lgamma(dn + 1) - std::lgamma(dj + 1) - std::lgamma(dn - dj + 1) + dj * std::log(p) +
                      (dn - dj) * std::log1p(-p));
    }
    return sum;
  };
  double lo = static_cast<double>(k) / dn, hi = 1.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) > 0.05 ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace skylane::integrity::sim
