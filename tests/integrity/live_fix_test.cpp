// Live fixes from raw pseudoranges (integrity/raim/live_fix.hpp) and the NMEA protection-level
// rules (planner/tracking/track_fix.hpp). The pseudoranges are made from real almanac geometry
// (alm01jan2020, as raim_monte_carlo_test) at a user near Zurich, with the noise drawn from the
// σ_int the RAIM test itself weights with, so the stated probabilities can be checked:
//  * noiseless: the WLS converges to the truth and the PL is the RAIM PL of the true geometry;
//  * fault-free: the PL bounds the error and false alerts are as rare as P_fa says;
//  * faulted: the first pass (detection only, PL grown by PL_det when the fault is detected)
//    and the FDE rerun keep the misleading rate within P_md, and the rerun excludes the faulty
//    satellite;
//  * NMEA: HPL = √(−2 ln p)·σ_major and VPL = Q⁻¹(p/2)·σ_alt exceed with probability ≤ p (≈ p).
#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/atmosphere.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "integrity/pl_summary.hpp"
#include "integrity/raim/live_fix.hpp"
#include "integrity/raim/raim.hpp"
#include "integrity/raim/wls.hpp"
#include "integrity/stats.hpp"
#include "planner/tracking/track_fix.hpp"

#include "tests/test_util.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace skylane::integrity {
namespace {

/// GPS week of 2020-01-01 (the almanac's week 38 modulo 1024) and that day's offset in it.
constexpr int kWeek = 2086;
constexpr double kDayInWeek_s = 3 * 86400.0;
/// Four epochs of the day: 8–10 GPS satellites above the mask at the site.
constexpr std::array<double, 4> kEpochsOfDay_s{0.0, 21600.0, 43200.0, 64800.0};
/// The satellites given are those above 5.5°: a position a kilometre (or a fault's shift)
/// away moves elevations by < 0.01°, so the solver's 5° mask never drops one of them.
constexpr double kSelectionMask_deg = 5.5;
/// The receiver clock in every pseudorange (100 µs).
constexpr double kReceiverClock_m = 3.0e4;

/// A user at one epoch: the satellites in view (at transmit time, reception frame) and the
/// geometry at the true position, row i = sats[i].
struct Sky {
  GpsTime t;
  maps::Geodetic truth;
  Eigen::Vector3d p_truth = Eigen::Vector3d::Zero();
  std::vector<VisibleSatellite> sats;
  Geometry g;
};

const OrbitSource& almanacOrbits() {
  static const OrbitSource source = [] {
    OrbitSource o;
    o.addAlmanac(loadAlmanac(test::dataPath("gnss/alm01jan2020.txt")));
    return o;
  }();
  return source;
}

Sky skyAt(double seconds_of_day, const LiveFixConfig& cfg) {
  Sky s;
  s.t = GpsTime{kWeek, kDayInWeek_s + seconds_of_day};
  s.truth = {maps::deg2rad(47.37), maps::deg2rad(8.54), 500.0};
  s.p_truth = maps::geodeticToEcef(s.truth);
  s.sats = almanacOrbits().visible(s.p_truth, s.t, maps::deg2rad(kSelectionMask_deg));
  std::vector<SatLook> looks;
  for (const VisibleSatellite& v : s.sats) looks.push_back({v.sat, maps::lookAngles(s.p_truth, v.p_ecef)});
  // The same τ_vert the solver uses (ignored by the default dual-frequency model).
  const double tau = cfg.model.iono_tau_vert_m.value_or(ionoTauVert_m(geomagneticLatitude(s.truth)));
  s.g = buildGeometry(looks, cfg.model, tau);
  return s;
}

std::vector<Sky> skies(const LiveFixConfig& cfg) {
  std::vector<Sky> out;
  for (double t : kEpochsOfDay_s) out.push_back(skyAt(t, cfg));
  return out;
}

/// Pseudoranges |r_s − r| + c·δt + error_i, each with the satellite's position.
std::vector<RawRange> rangesOf(const Sky& s, const Eigen::VectorXd& error_m) {
  std::vector<RawRange> out;
  for (std::size_t i = 0; i < s.sats.size(); ++i) {
    RawRange r;
    r.sat = s.sats[i].sat;
    r.pr_m = (s.sats[i].p_ecef - s.p_truth).norm() + kReceiverClock_m + error_m[static_cast<Eigen::Index>(i)];
    r.sat_ecef_m = s.sats[i].p_ecef;
    out.push_back(r);
  }
  return out;
}

/// The fix's position error in east, north, up at the truth [m].
Eigen::Vector3d enuError(const Sky& s, const LiveFix& fix) { return maps::LocalFrame(s.truth).ecefToEnu(fix.p_ecef); }

/// Gaussian range errors with the geometry's integrity σ's (the σ's the RAIM test weights with).
Eigen::VectorXd noise(const Sky& s, std::mt19937_64& rng) {
  std::normal_distribution<double> n01;
  Eigen::VectorXd e(s.g.numSats());
  for (int i = 0; i < s.g.numSats(); ++i) e[i] = s.g.sigma_int[i] * n01(rng);
  return e;
}

/// Largest horizontal and vertical shift of the WLS solution when one row is left out, with
/// the true geometry and the errors themselves as prefit residuals (the true clock is known
/// here): the PL_det term of live_fix.hpp, computed independently of the solver.
Eigen::Vector2d largestLeaveOneOutShift(const Geometry& g, const Eigen::VectorXd& y) {
  Eigen::Vector2d worst = Eigen::Vector2d::Zero();
  const WlsSolution all = solveWls(g.G, g.sigma_int);
  if (!all.ok) return worst;
  const Eigen::Vector3d x_all = (all.S * y).head<3>();
  const Eigen::Index n = g.G.rows();
  for (Eigen::Index left_out = 0; left_out < n; ++left_out) {
    Eigen::MatrixXd Gi(n - 1, g.G.cols());
    Eigen::VectorXd si(n - 1), yi(n - 1);
    for (Eigen::Index r = 0, k = 0; r < n; ++r) {
      if (r == left_out) continue;
      Gi.row(k) = g.G.row(r);
      si[k] = g.sigma_int[r];
      yi[k] = y[r];
      ++k;
    }
    const WlsSolution wi = solveWls(Gi, si);
    if (!wi.ok) continue;
    const Eigen::Vector3d d = (wi.S * yi).head<3>() - x_all;
    worst.x() = std::max(worst.x(), d.head<2>().norm());
    worst.y() = std::max(worst.y(), std::abs(d.z()));
  }
  return worst;
}

/// One-sided upper allowance for a rate whose true value is at most p, measured on n samples:
/// p + 3·√(p(1 − p)/n) (normal approximation of the binomial, 3σ).
double upperAllowance(double p, int n) { return p + 3.0 * std::sqrt(p * (1.0 - p) / n); }

/// Binomial 3σ of a rate p measured on n samples.
double threeSigma(double p, int n) { return 3.0 * std::sqrt(p * (1.0 - p) / n); }

TEST(LiveFix, ConvergesToTheTruthFromAKilometreAwayWithoutNoise) {
  constexpr double kPositionTol_m = 1e-3;
  constexpr double kPlRelTol = 1e-6;
  // GIVEN noiseless pseudoranges (range + a 3e4 m receiver clock) of every satellite above
  // 5.5° at 47.37 N 8.54 E, 500 m, with the satellites' positions, at four epochs
  const LiveFixConfig cfg{};
  for (const Sky& s : skies(cfg)) {
    ASSERT_GE(s.g.numSats(), 8) << "epoch " << s.t.sow;
    const Eigen::VectorXd no_error = Eigen::VectorXd::Zero(s.g.numSats());
    // AND a reported position a kilometre from the truth (600 m E, −480 m N, 640 m U)
    const maps::Geodetic initial = maps::LocalFrame(s.truth).fromEnu(Eigen::Vector3d(600.0, -480.0, 640.0));

    // WHEN the first pass solves the epoch
    const LiveFix fix = solveLiveFix(rangesOf(s, no_error), initial, s.t, cfg, false, nullptr);

    // THEN it converges to the truth, all satellites used, nothing detected or excluded
    ASSERT_TRUE(fix.solved) << fix.note;
    EXPECT_LT((fix.p_ecef - s.p_truth).norm(), kPositionTol_m) << "epoch " << s.t.sow;
    EXPECT_EQ(fix.used.size(), s.sats.size());
    EXPECT_TRUE(fix.excluded.empty());
    EXPECT_TRUE(fix.missing_orbit.empty());
    EXPECT_FALSE(fix.fault_detected);
    EXPECT_FALSE(fix.fault_excluded);
    // AND the PL is the RAIM PL of the geometry at the truth (no detection term)
    const RaimPl ref = raimProtectionLevels(s.g, cfg.raim);
    ASSERT_TRUE(ref.available) << ref.reason;
    const PlSummary summary = protectionLevels(s.g, cfg.method, cfg.model, cfg.raim, cfg.araim);
    ASSERT_TRUE(fix.pl.pl_computed) << fix.pl.reason;
    EXPECT_EQ(fix.pl.available, summary.available);
    EXPECT_NEAR(fix.pl.hpl_m, ref.hpl_m, kPlRelTol * ref.hpl_m);
    EXPECT_NEAR(fix.pl.vpl_m, ref.vpl_m, kPlRelTol * ref.vpl_m);
    EXPECT_NEAR(fix.pl.hpl_m, summary.hpl_m, kPlRelTol * summary.hpl_m);
    EXPECT_NEAR(fix.pl.vpl_m, summary.vpl_m, kPlRelTol * summary.vpl_m);
    EXPECT_DOUBLE_EQ(fix.fault_free_hpl_m, fix.pl.hpl_m);
    EXPECT_DOUBLE_EQ(fix.fault_free_vpl_m, fix.pl.vpl_m);
  }
}

TEST(LiveFix, MonteCarloFaultFreePlBoundsTheErrorAndFalseAlertsAreRare) {
  // 20,000 epochs (5,000 per sky). The fault-free PL is ≥ K_ff·σ with K_ff,H = Q⁻¹(1e-9) ≈ 6.0
  // (P(|e_H| > 6 σ_major) ≤ e^−18 ≈ 1.5e-8) and K_ff,V = Q⁻¹(4.9e-8) ≈ 5.3: the expected number
  // of exceedances is < 1e-3, so none is allowed. With P_fa = 1e-6 the expected number of false
  // alerts is 0.02; P(≥ 3) ≈ 1.3e-6, so at most 2 are allowed.
  constexpr int kEpochs = 20000;
  constexpr int kMaxFalseAlerts = 2;
  // GIVEN the four skies and Gaussian range errors with σ_int per satellite, no fault
  const LiveFixConfig cfg{};
  const std::vector<Sky> all_skies = skies(cfg);
  std::mt19937_64 rng(7);
  int unsolved = 0, false_alerts = 0, exceed_h = 0, exceed_v = 0;
  double worst_ratio_h = 0.0, worst_ratio_v = 0.0;

  // WHEN every epoch is solved with the first pass from the true position
  for (int k = 0; k < kEpochs; ++k) {
    const Sky& s = all_skies[static_cast<std::size_t>(k) % all_skies.size()];
    const LiveFix fix = solveLiveFix(rangesOf(s, noise(s, rng)), s.truth, s.t, cfg, false, nullptr);
    if (!fix.solved) {
      ++unsolved;
      continue;
    }
    const Eigen::Vector3d e = enuError(s, fix);
    const double eh = std::hypot(e.x(), e.y()), ev = std::abs(e.z());
    false_alerts += fix.fault_detected;
    exceed_h += eh > fix.pl.hpl_m;
    exceed_v += ev > fix.pl.vpl_m;
    worst_ratio_h = std::max(worst_ratio_h, eh / fix.pl.hpl_m);
    worst_ratio_v = std::max(worst_ratio_v, ev / fix.pl.vpl_m);
  }

  // THEN the PLs bound every error and false alerts stay within what P_fa allows
  std::printf("live fix fault-free, %d epochs: false alerts %d, error > HPL %d, > VPL %d, worst error/PL H %.3f V %.3f\n",
              kEpochs, false_alerts, exceed_h, exceed_v, worst_ratio_h, worst_ratio_v);
  EXPECT_EQ(unsolved, 0);
  EXPECT_EQ(exceed_h, 0);
  EXPECT_EQ(exceed_v, 0);
  EXPECT_LE(false_alerts, kMaxFalseAlerts);
}

TEST(LiveFix, AraimDetectsAndExcludesAnInjectedFaultBySolutionSeparation) {
  // GIVEN the ARAIM method (MHSS solution separation) and a 80 m bias on each satellite in turn
  LiveFixConfig cfg;
  cfg.method = IntegrityMethod::kAraim;
  constexpr double kFault_m = 80.0;
  int cases = 0, excluded_right = 0;
  for (const Sky& s : skies(cfg)) {
    const LiveFix clean = solveLiveFix(rangesOf(s, Eigen::VectorXd::Zero(s.g.numSats())), s.truth, s.t, cfg, false, nullptr);
    ASSERT_TRUE(clean.solved && clean.pl.pl_computed) << clean.note << clean.pl.reason;
    EXPECT_FALSE(clean.fault_detected);
    for (int i = 0; i < s.g.numSats(); ++i) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(s.g.numSats());
      e[i] = kFault_m;
      const std::vector<RawRange> ranges = rangesOf(s, e);
      // WHEN the first pass and the rerun solve it
      const LiveFix first = solveLiveFix(ranges, s.truth, s.t, cfg, false, nullptr);
      const LiveFix rerun = solveLiveFix(ranges, s.truth, s.t, cfg, true, nullptr);
      ASSERT_TRUE(first.solved && rerun.solved);
      const Eigen::Vector3d err_first = enuError(s, first), err_rerun = enuError(s, rerun);
      // THEN every PL the passes give bounds their own error (a noiseless bias: the PL must
      // hold it deterministically), and a detected fault is excluded and named
      EXPECT_LE(err_first.head<2>().norm(), first.pl.hpl_m) << "sat " << s.g.sats[static_cast<std::size_t>(i)].str();
      EXPECT_LE(std::abs(err_first.z()), first.pl.vpl_m);
      if (!first.fault_detected) continue;
      ++cases;
      EXPECT_GT(first.pl.hpl_m, clean.pl.hpl_m);  // PL_det grows with the fault
      if (rerun.fault_excluded && rerun.excluded.size() == 1 && rerun.excluded[0] == s.g.sats[static_cast<std::size_t>(i)]) {
        ++excluded_right;
        EXPECT_LT(err_rerun.norm(), 1e-3);  // noiseless: the remaining satellites give the truth
        EXPECT_LE(err_rerun.head<2>().norm(), rerun.pl.hpl_m);
      }
    }
  }
  EXPECT_GT(cases, 20);
  EXPECT_EQ(excluded_right, cases);
}

TEST(LiveFix, MonteCarloWithFaultInjection) {
  // 15,000 epochs, each with a bias uniform in [0, 150] m on one satellite drawn at random, the
  // same pseudoranges solved by the first pass (detection only) and by the FDE rerun.
  // Misleading-rate bound: for any bias the RAIM PL (slope·p_bias + K_md·σ) is exceeded while
  // undetected with probability ≤ P_md = 1e-3, and a detected fault's PL_det exceeds the error
  // (|e| ≤ |e of the solution without the faulty satellite| + its shift); so the rate is ≤ P_md.
  // Allowance: P_md + 3·√(P_md(1 − P_md)/15,000) = 1e-3 + 7.7e-4 = 1.77e-3 (≤ 26 of 15,000).
  // The same bound holds after an exclusion (a wrong exclusion leaves a fault the reduced
  // geometry's PL covers with P_md again). A Python model of this set-up (same almanac, σ's and
  // thresholds, 80,000 epochs) showed no misleading epoch in either pass and every exclusion of
  // a fault > 50 m correct.
  constexpr int kEpochs = 15000;
  constexpr double kMaxFault_m = 150.0;
  constexpr double kLargeFault_m = 50.0;
  constexpr double kMinCorrectExclusionShare = 0.99;
  /// PL_det against the independent leave-one-out shift: the solver linearises at its own
  /// (faulted) solution, up to a few hundred metres from the truth: mm-level differences.
  constexpr double kShiftAbsTol_m = 0.05;
  constexpr double kShiftRelTol = 1e-3;
  // GIVEN the four skies, σ_int noise and one biased satellite per epoch
  const LiveFixConfig cfg{};
  const double pmd = cfg.raim.pmd;
  const std::vector<Sky> all_skies = skies(cfg);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> fault_size(0.0, kMaxFault_m);
  int unsolved = 0, detected = 0, detected_but_available = 0, pl_det_mismatch = 0, detection_differs = 0;
  int misleading_h = 0, misleading_v = 0;
  int exclusions = 0, not_one_excluded = 0, large = 0, large_correct = 0;
  int after_exclusion_h = 0, after_exclusion_v = 0, rerun_misleading_h = 0, rerun_misleading_v = 0;
  std::string first_mismatch;

  for (int k = 0; k < kEpochs; ++k) {
    const Sky& s = all_skies[static_cast<std::size_t>(k) % all_skies.size()];
    Eigen::VectorXd e = noise(s, rng);
    std::uniform_int_distribution<int> pick(0, s.g.numSats() - 1);
    const int faulty = pick(rng);
    const double bias = fault_size(rng);
    e[faulty] += bias;
    const std::vector<RawRange> ranges = rangesOf(s, e);

    // WHEN the first pass and the monitoring rerun solve the epoch
    const LiveFix first = solveLiveFix(ranges, s.truth, s.t, cfg, false, nullptr);
    const LiveFix rerun = solveLiveFix(ranges, s.truth, s.t, cfg, true, nullptr);
    if (!first.solved || !rerun.solved) {
      ++unsolved;
      continue;
    }

    // (a) first pass: a detected fault grows the PL by the largest leave-one-out shift
    const Eigen::Vector3d e1 = enuError(s, first);
    if (first.fault_detected) {
      ++detected;
      detected_but_available += first.pl.available;
      const Eigen::Vector2d ref = largestLeaveOneOutShift(s.g, e);
      const double dh = first.pl.hpl_m - first.fault_free_hpl_m, dv = first.pl.vpl_m - first.fault_free_vpl_m;
      if (std::abs(dh - ref.x()) > kShiftAbsTol_m + kShiftRelTol * ref.x() ||
          std::abs(dv - ref.y()) > kShiftAbsTol_m + kShiftRelTol * ref.y()) {
        if (pl_det_mismatch == 0) {
          first_mismatch = "epoch " + std::to_string(k) + ": PL growth H " + std::to_string(dh) + " V " + std::to_string(dv) +
                           ", leave-one-out shift H " + std::to_string(ref.x()) + " V " + std::to_string(ref.y());
        }
        ++pl_det_mismatch;
      }
    }
    misleading_h += std::hypot(e1.x(), e1.y()) > first.pl.hpl_m;
    misleading_v += std::abs(e1.z()) > first.pl.vpl_m;

    // (b) rerun: the same detection, then exclusion of the satellite the w-test points at
    detection_differs += rerun.fault_detected != first.fault_detected;
    const Eigen::Vector3d e2 = enuError(s, rerun);
    const bool over_h = std::hypot(e2.x(), e2.y()) > rerun.pl.hpl_m, over_v = std::abs(e2.z()) > rerun.pl.vpl_m;
    rerun_misleading_h += over_h;
    rerun_misleading_v += over_v;
    if (rerun.fault_excluded) {
      ++exclusions;
      after_exclusion_h += over_h;
      after_exclusion_v += over_v;
      if (rerun.excluded.size() != 1) {
        ++not_one_excluded;
      } else if (bias > kLargeFault_m) {
        ++large;
        large_correct += rerun.excluded.front() == s.sats[static_cast<std::size_t>(faulty)].sat;
      }
    }
  }

  const double bound_all = upperAllowance(pmd, kEpochs);
  std::printf("live fix faulted, %d epochs: detected %d; first pass misleading H %d V %d (rate %.2e %.2e, bound %.2e)\n",
              kEpochs, detected, misleading_h, misleading_v, double(misleading_h) / kEpochs, double(misleading_v) / kEpochs,
              bound_all);
  std::printf("  rerun: %d exclusions, %d/%d correct for faults > %.0f m; misleading after exclusion H %d V %d, "
              "overall H %d V %d\n",
              exclusions, large_correct, large, kLargeFault_m, after_exclusion_h, after_exclusion_v, rerun_misleading_h,
              rerun_misleading_v);
  EXPECT_EQ(unsolved, 0);
  // THEN (a) most faults up to 150 m are detected (sanity: the sample is not all below noise),
  // a detected fault makes the PL unavailable and grows it by exactly the leave-one-out shift,
  EXPECT_GT(detected, kEpochs / 2);
  EXPECT_EQ(detected_but_available, 0);
  EXPECT_EQ(pl_det_mismatch, 0) << first_mismatch;
  // AND the first pass's misleading rate is within P_md (with the 3σ allowance)
  EXPECT_LE(double(misleading_h) / kEpochs, bound_all);
  EXPECT_LE(double(misleading_v) / kEpochs, bound_all);
  // AND (b) the rerun detects as the first pass did and excludes one satellite at a time,
  EXPECT_EQ(detection_differs, 0);
  EXPECT_EQ(not_one_excluded, 0);
  // the faulty one in ≥ 99 % of the exclusions of a fault > 50 m (2/3 of the epochs),
  ASSERT_GT(large, kEpochs / 3);
  EXPECT_GE(double(large_correct), kMinCorrectExclusionShare * large);
  // AND the error is within the PL after it, at the same P_md bound
  ASSERT_GT(exclusions, 0);
  const double bound_excluded = upperAllowance(pmd, exclusions);
  EXPECT_LE(double(after_exclusion_h) / exclusions, bound_excluded);
  EXPECT_LE(double(after_exclusion_v) / exclusions, bound_excluded);
  EXPECT_LE(double(rerun_misleading_h) / kEpochs, bound_all);
  EXPECT_LE(double(rerun_misleading_v) / kEpochs, bound_all);
}

TEST(LiveFix, ExcludeFaultsOnTheFirstPassIsTheRerunToTheBit) {
  // GIVEN RAIM and ARAIM, σ_int noise and a 0–150 m bias on one satellite per epoch
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> fault_size(0.0, 150.0);
  for (const IntegrityMethod method : {IntegrityMethod::kRaim, IntegrityMethod::kAraim}) {
    LiveFixConfig cfg;
    cfg.method = method;
    int detected = 0, excluded = 0;
    for (int k = 0; k < 400; ++k) {
      const std::vector<Sky> all_skies = skies(cfg);
      const Sky& s = all_skies[static_cast<std::size_t>(k) % all_skies.size()];
      Eigen::VectorXd e = noise(s, rng);
      e[std::uniform_int_distribution<int>(0, s.g.numSats() - 1)(rng)] += fault_size(rng);
      std::vector<RawRange> ranges = rangesOf(s, e);
      if (k % 3 == 0) ranges.push_back({SatId{Constellation::kGps, 99}, 2.2e7, std::nullopt});  // no orbit for it
      // WHEN the exclusion goes on from the first pass, and when the epoch is solved with it
      const LiveFix first = solveLiveFix(ranges, s.truth, s.t, cfg, false, nullptr);
      ASSERT_TRUE(first.solved && first.epoch);
      const LiveFix on = excludeFaults(first, cfg);
      const LiveFix whole = solveLiveFix(ranges, s.truth, s.t, cfg, true, nullptr);
      // THEN both are the same solution to the bit: position, clock, PLs, test, exclusions, notes
      ASSERT_EQ(on.solved, whole.solved) << k;
      EXPECT_EQ(on.p_ecef, whole.p_ecef) << k;
      EXPECT_EQ(on.position.lat_rad, whole.position.lat_rad) << k;
      EXPECT_EQ(on.position.lon_rad, whole.position.lon_rad) << k;
      EXPECT_EQ(on.position.h_ell_m, whole.position.h_ell_m) << k;
      EXPECT_EQ(on.clock_m, whole.clock_m) << k;
      EXPECT_EQ(on.pl.hpl_m, whole.pl.hpl_m) << k;
      EXPECT_EQ(on.pl.vpl_m, whole.pl.vpl_m) << k;
      EXPECT_EQ(on.pl.available, whole.pl.available) << k;
      EXPECT_EQ(on.pl.pl_computed, whole.pl.pl_computed) << k;
      EXPECT_EQ(on.pl.reason, whole.pl.reason) << k;
      EXPECT_EQ(on.fault_free_hpl_m, whole.fault_free_hpl_m) << k;
      EXPECT_EQ(on.fault_free_vpl_m, whole.fault_free_vpl_m) << k;
      EXPECT_EQ(on.missing_orbit, whole.missing_orbit) << k;
      EXPECT_EQ(whole.missing_orbit.size(), k % 3 == 0 ? 1u : 0u) << k;
      EXPECT_EQ(on.test_statistic, whole.test_statistic) << k;
      EXPECT_EQ(on.threshold, whole.threshold) << k;
      EXPECT_EQ(on.fault_detected, whole.fault_detected) << k;
      EXPECT_EQ(on.fault_excluded, whole.fault_excluded) << k;
      EXPECT_EQ(on.excluded, whole.excluded) << k;
      EXPECT_EQ(on.used, whole.used) << k;
      EXPECT_EQ(on.note, whole.note) << k;
      detected += whole.fault_detected;
      excluded += whole.fault_excluded;
    }
    // (the sample holds detections and exclusions of both methods, and satellites without an orbit)
    EXPECT_GT(detected, 100) << static_cast<int>(method);
    EXPECT_GT(excluded, 50) << static_cast<int>(method);
  }
  // AND a pass made with the exclusion has nothing to go on from
  LiveFixConfig cfg;
  const Sky s = skies(cfg).front();
  const LiveFix whole = solveLiveFix(rangesOf(s, Eigen::VectorXd::Zero(s.g.numSats())), s.truth, s.t, cfg, true, nullptr);
  EXPECT_FALSE(whole.epoch);
  EXPECT_THROW((void)excludeFaults(whole, cfg), std::invalid_argument);
}

/// An NMEA epoch with a GST error ellipse (semi-major a along orientation_deg from north,
/// semi-minor b) and altitude σ.
NmeaFix nmeaFixWithGst(double a_m, double b_m, double orientation_deg, double sigma_alt_m) {
  NmeaFix fix;
  fix.quality = 1;
  fix.satellites = 10;
  fix.lat_rad = maps::deg2rad(47.37);
  fix.lon_rad = maps::deg2rad(8.54);
  fix.h_ell_m = 500.0;
  NmeaGst gst;
  const double th = maps::deg2rad(orientation_deg);
  gst.rms_m = 1.0;
  gst.semi_major_m = a_m;
  gst.semi_minor_m = b_m;
  gst.orientation_deg = orientation_deg;
  gst.sigma_lat_m = std::sqrt(a_m * a_m * std::cos(th) * std::cos(th) + b_m * b_m * std::sin(th) * std::sin(th));
  gst.sigma_lon_m = std::sqrt(a_m * a_m * std::sin(th) * std::sin(th) + b_m * b_m * std::cos(th) * std::cos(th));
  gst.sigma_alt_m = sigma_alt_m;
  fix.gst = gst;
  return fix;
}

TEST(NmeaPlRule, MonteCarloEllipseBoundHolds) {
  // P(|e| > K·a) = P(a²z₁² + b²z₂² > K²a²) ≤ P(z₁² + z₂² > K²) = e^(−K²/2) = p, with equality
  // for a circle: each rate must be ≤ p + 3σ (binomial, 1e6 draws).
  constexpr int kDraws = 1000000;
  constexpr double kSemiMajor_m = 2.0;
  constexpr double kPlRelTol = 1e-12;
  constexpr std::array<double, 4> kAxisRatios{1.0, 2.0, 5.0, 10.0};
  constexpr std::array<double, 2> kRisks{1e-2, 1e-3};
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> orientation(0.0, 180.0);
  for (double ratio : kAxisRatios) {
    // GIVEN a GST ellipse a × a/ratio at a random orientation
    const double a = kSemiMajor_m, b = kSemiMajor_m / ratio, orientation_deg = orientation(rng);
    const NmeaFix fix = nmeaFixWithGst(a, b, orientation_deg, 1.0);
    // WHEN the fix's HPL is formed for each risk
    std::array<double, 2> hpl{};
    for (std::size_t r = 0; r < kRisks.size(); ++r) {
      const planner::TrackFix f = planner::trackFixFromNmea(fix, "mc", planner::NmeaPlRisk{kRisks[r], kRisks[r]});
      ASSERT_TRUE(f.hpl_m.has_value());
      EXPECT_EQ(f.pl_source, planner::PlSource::kNmeaGst);
      const double expected = std::sqrt(-2.0 * std::log(kRisks[r])) * a;
      EXPECT_NEAR(*f.hpl_m, expected, kPlRelTol * expected) << "a/b " << ratio;
      hpl[r] = *f.hpl_m;
    }
    // AND 1e6 bivariate normal errors of that ellipse are drawn
    const double th = maps::deg2rad(orientation_deg);
    std::array<int, 2> exceed{};
    for (int k = 0; k < kDraws; ++k) {
      const double along = a * n01(rng), across = b * n01(rng);
      const double north = along * std::cos(th) - across * std::sin(th);
      const double east = along * std::sin(th) + across * std::cos(th);
      const double radial = std::hypot(north, east);
      for (std::size_t r = 0; r < kRisks.size(); ++r) exceed[r] += radial > hpl[r];
    }
    // THEN each HPL is exceeded with probability ≤ p (within 3σ)
    for (std::size_t r = 0; r < kRisks.size(); ++r) {
      const double p = kRisks[r], rate = double(exceed[r]) / kDraws;
      std::printf("NMEA HPL a/b %.0f, p %.0e: exceedance %.3e\n", ratio, p, rate);
      EXPECT_LE(rate, upperAllowance(p, kDraws)) << "a/b " << ratio << ", p " << p;
    }
  }
}

TEST(NmeaPlRule, MonteCarloVerticalRuleExceedsTwoSidedWithTheStatedRisk) {
  // VPL = Q⁻¹(p/2)·σ_alt: P(|e_U| > VPL) = p exactly for a Gaussian; 1e6 draws, within 3σ.
  constexpr int kDraws = 1000000;
  constexpr double kSigmaAlt_m = 3.0;
  constexpr double kPlRelTol = 1e-12;
  constexpr std::array<double, 2> kRisks{1e-2, 1e-3};
  std::mt19937_64 rng(4048);
  std::normal_distribution<double> n01;
  // GIVEN a GST with σ_alt = 3 m
  const NmeaFix fix = nmeaFixWithGst(2.0, 1.0, 30.0, kSigmaAlt_m);
  for (double p : kRisks) {
    // WHEN the VPL is formed for risk p
    const planner::TrackFix f = planner::trackFixFromNmea(fix, "mc", planner::NmeaPlRisk{p, p});
    ASSERT_TRUE(f.vpl_m.has_value());
    const double expected = normalTailInverse(p / 2.0) * kSigmaAlt_m;
    EXPECT_NEAR(*f.vpl_m, expected, kPlRelTol * expected);
    // AND 1e6 vertical errors are drawn
    int exceed = 0;
    for (int k = 0; k < kDraws; ++k) exceed += std::abs(kSigmaAlt_m * n01(rng)) > *f.vpl_m;
    // THEN the two-sided exceedance is p within 3σ
    const double rate = double(exceed) / kDraws;
    std::printf("NMEA VPL p %.0e: exceedance %.3e\n", p, rate);
    EXPECT_NEAR(rate, p, threeSigma(p, kDraws)) << "p " << p;
  }
}

}  // namespace
}  // namespace skylane::integrity
