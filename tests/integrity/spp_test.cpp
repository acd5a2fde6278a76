// Single-point positioning on the real GSI station files, against the header position and
// RTKLIB's own single-point solutions (tests/data/rtklib/spp_summary.txt: rnx2rtkp -p 0 with
// broadcast ionosphere, Saastamoinen troposphere, 15° mask).
#include "integrity/raim/spp.hpp"

#include "integrity/gnss/atmosphere.hpp"
#include "integrity/raim/live_fix.hpp"

#include "tests/test_util.hpp"

#include <algorithm>
#include <cmath>

namespace skylane::integrity {
namespace {

struct ErrorStats {
  double h_rms = 0, h_p95 = 0, h_max = 0, v_rms = 0;
  int epochs = 0;
};

/// Errors in ENU at the header position over epochs with at least `min_sats` satellites
/// (RTKLIB refuses the 5-satellite epochs of these files: GDOP > 30).
ErrorStats errors(const std::vector<SppEpoch>& sol, const Eigen::Vector3d& truth, int min_sats) {
  const maps::LocalFrame f(maps::ecefToGeodetic(truth));
  std::vector<double> h;
  double v2 = 0;
  for (const auto& e : sol) {
    if (!e.solved || static_cast<int>(e.used.size()) < min_sats) continue;
    const Eigen::Vector3d d = f.ecefToEnu(e.p_ecef);
    h.push_back(std::hypot(d.x(), d.y()));
    v2 += d.z() * d.z();
  }
  ErrorStats s;
  s.epochs = static_cast<int>(h.size());
  if (h.empty()) return s;
  double h2 = 0;
  for (double x : h) h2 += x * x;
  std::sort(h.begin(), h.end());
  s.h_rms = std::sqrt(h2 / h.size());
  s.h_p95 = h[static_cast<std::size_t>(std::ceil(0.95 * h.size())) - 1];  // nearest rank
  s.h_max = h.back();
  s.v_rms = std::sqrt(v2 / h.size());
  return s;
}

struct Station {
  const char* obs;
  const char* nav;
  double rtklib_h_rms, rtklib_h_p95, rtklib_h_max;  // ns ≥ 6 rows of spp_summary.txt
};

TEST(Spp, KlobucharSolutionsAreAtRtklibLevelOnBothGsiStations) {
  const Station stations[] = {{"gnss/30400920.05o", "gnss/30400920.05n", 0.528, 0.788, 0.990},
                              {"gnss/07590920.05o", "gnss/07590920.05n", 0.445, 0.716, 1.098}};
  for (const auto& st : stations) {
    const ObservationData obs = loadRinexObs(test::dataPath(st.obs));
    const NavigationData nav = loadRinexNav(test::dataPath(st.nav));
    SppConfig cfg;
    cfg.iono = IonoMode::kKlobuchar;
    const auto sol = solveSpp(obs, nav, cfg);
    ASSERT_EQ(sol.size(), 120u);
    EXPECT_TRUE(std::all_of(sol.begin(), sol.end(), [](const SppEpoch& e) { return e.solved; }));
    const ErrorStats s = errors(sol, *obs.approx_position_ecef, 6);
    std::printf("%s: H rms %.3f p95 %.3f max %.3f V rms %.3f over %d epochs (RTKLIB %.3f %.3f %.3f)\n", st.obs, s.h_rms,
                s.h_p95, s.h_max, s.v_rms, s.epochs, st.rtklib_h_rms, st.rtklib_h_p95, st.rtklib_h_max);
    EXPECT_EQ(s.epochs, 114);
    EXPECT_LE(s.h_rms, 1.15 * st.rtklib_h_rms) << st.obs;
    EXPECT_LE(s.h_p95, 1.15 * st.rtklib_h_p95) << st.obs;
    EXPECT_LE(s.h_max, 1.25 * st.rtklib_h_max) << st.obs;
    EXPECT_LE(s.v_rms, 1.5) << st.obs;
  }
}

TEST(Spp, ProtectionLevelsBoundTheActualErrorAtEveryEpoch) {
  const ObservationData obs = loadRinexObs(test::dataPath("gnss/30400920.05o"));
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  for (IonoMode mode : {IonoMode::kAuto, IonoMode::kKlobuchar}) {
    SppConfig cfg;
    cfg.iono = mode;
    const maps::LocalFrame f(maps::ecefToGeodetic(*obs.approx_position_ecef));
    for (const auto& e : solveSpp(obs, nav, cfg)) {
      ASSERT_TRUE(e.solved);
      ASSERT_TRUE(e.pl.pl_computed) << e.note;
      const Eigen::Vector3d d = f.ecefToEnu(e.p_ecef);
      EXPECT_LT(std::hypot(d.x(), d.y()), e.pl.hpl_m);
      EXPECT_LT(std::abs(d.z()), e.pl.vpl_m);
    }
  }
}

TEST(Spp, IonoFreeIsUsedWhenTwoFrequenciesExist) {
  const ObservationData obs = loadRinexObs(test::dataPath("gnss/30400920.05o"));
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  const auto sol = solveSpp(obs, nav, SppConfig{});
  const ErrorStats s = errors(sol, *obs.approx_position_ecef, 6);
  EXPECT_TRUE(sol.front().iono_free);
  // The C1/P2 iono-free combination triples the code noise: metre-level, not RTKLIB's L1 level.
  EXPECT_LT(s.h_rms, 1.5);
  EXPECT_LT(s.h_max, 3.0);
}

TEST(Spp, FiftyMetreBiasOnOneSatelliteIsDetectedAndExcluded) {
  const ObservationData obs = loadRinexObs(test::dataPath("gnss/30400920.05o"));
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  SppConfig cfg;
  const SatId g08{Constellation::kGps, 8};
  cfg.injected_bias_m[g08] = 50.0;
  const auto sol = solveSpp(obs, nav, cfg);
  const auto clean = errors(solveSpp(obs, nav, SppConfig{}), *obs.approx_position_ecef, 6);
  int with_g08 = 0, excluded = 0;
  for (const auto& e : sol) {
    const bool in_view = std::find(e.used.begin(), e.used.end(), g08) != e.used.end() ||
                         std::find(e.excluded.begin(), e.excluded.end(), g08) != e.excluded.end();
    if (!in_view || e.used.size() + e.excluded.size() < 6) continue;
    ++with_g08;
    EXPECT_TRUE(e.fault_detected) << formatRfc3339(e.t);
    if (e.excluded == std::vector<SatId>{g08}) ++excluded;
  }
  ASSERT_GT(with_g08, 30);  // G08 is above 15° for about 20 minutes of the hour
  EXPECT_GE(excluded, with_g08 * 95 / 100);
  // After exclusion the positions are as good as without the fault.
  const ErrorStats s = errors(sol, *obs.approx_position_ecef, 6);
  EXPECT_LT(s.h_rms, clean.h_rms * 1.5 + 0.2);
}

TEST(Spp, Rinex3GpsPlusGalileoWithTwoReceiverClocks) {
  const ObservationData obs = loadRinexObs(test::dataPath("rinex3/base_20240624_MO.rnx"));
  const NavigationData nav = loadRinexNav(test::dataPath("rinex3/base_20240624_MN.rnx"));
  const auto sol = solveSpp(obs, nav, SppConfig{});
  ASSERT_EQ(sol.size(), 10u);
  const maps::LocalFrame f(maps::ecefToGeodetic(*obs.approx_position_ecef));
  for (const auto& e : sol) {
    ASSERT_TRUE(e.solved) << e.note;
    const bool has_gal = std::any_of(e.used.begin(), e.used.end(),
                                     [](const SatId& s) { return s.constellation == Constellation::kGalileo; });
    EXPECT_TRUE(has_gal);
    EXPECT_GE(e.used.size(), 12u);
    const Eigen::Vector3d d = f.ecefToEnu(e.p_ecef);
    // RTKLIB's GPS+Galileo SPP on these files is 2.3 m H, 1.6 m V from the header position
    // (tests/data/rtklib/spp_summary_rinex3.txt), a near-constant ionospheric bias.
    EXPECT_LT(std::hypot(d.x(), d.y()), 3.0);
    EXPECT_LT(std::abs(d.z()), 3.0);
    EXPECT_TRUE(e.pl.pl_computed);
    // Galileo orbits, clocks and the second receiver clock are consistent with GPS: nothing is
    // excluded and the residual test passes.
    EXPECT_TRUE(e.excluded.empty());
    EXPECT_LT(e.test_statistic, e.threshold);
  }
}

/// The epoch's L1 code ranges as a live fix would carry them, corrected here from the broadcast
/// ephemeris (IS-GPS-200 §20.3.3.3.3: transmit time, satellite clock and T_GD, Sagnac), the
/// Klobuchar ionosphere and the Saastamoinen troposphere, all seen from `x`: an independent
/// preparation of the ranges the one epoch solver is given.
std::vector<RawRange> correctedL1Ranges(const ObservationEpoch& ep, const ObservationData& obs, const NavigationData& nav,
                                        const Eigen::Vector3d& x) {
  std::vector<RawRange> out;
  const int c1 = findObsType(obs.types[static_cast<int>(Constellation::kGps)], 'C', 1, "CWPXSLYM");
  const maps::Geodetic user = maps::ecefToGeodetic(x);
  for (const SatObservation& so : ep.sats) {
    if (so.sat.constellation != Constellation::kGps) continue;
    const double pr = so.values[static_cast<std::size_t>(c1)];
    const BroadcastEphemeris* eph = selectEphemeris(nav, so.sat, ep.t);
    if (!std::isfinite(pr) || !eph) continue;
    GpsTime t_tx = ep.t.plus(-pr / kSpeedOfLight_mps);
    t_tx = t_tx.plus(-satelliteState(*eph, t_tx).clock_s);
    const SatelliteState st = satelliteState(*eph, t_tx);
    const Eigen::Vector3d p = earthRotationCorrection(st.p_ecef, (st.p_ecef - x).norm() / kSpeedOfLight_mps);
    const maps::LookAngles look = maps::lookAngles(x, p);
    if (look.elevation_rad < 0.0) continue;
    const double corrected = pr + kSpeedOfLight_mps * (st.clock_s - eph->tgd_s) - klobucharDelay_m(*nav.klobuchar, user, look, ep.t) -
                             saastamoinenDelay_m(user, look.elevation_rad);
    out.push_back({so.sat, corrected, p});
  }
  return out;
}

TEST(Spp, SolvesEveryEpochWithTheLiveFixSolver) {
  // SPP and live tracking make one integrity call: an epoch solved by SPP, given again as the
  // corrected ranges a live fix carries, gives the same position, satellites, test and PL.
  const ObservationData obs = loadRinexObs(test::dataPath("gnss/30400920.05o"));
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  ASSERT_TRUE(nav.klobuchar);
  SppConfig cfg;
  cfg.iono = IonoMode::kKlobuchar;
  LiveFixConfig live;
  live.model.setUserModel(UserErrorModel::kSingleFrequency);
  live.elevation_mask_rad = cfg.elevation_mask_rad;
  int compared = 0;
  for (std::size_t i = 0; i < obs.epochs.size(); ++i) {
    const SppEpoch e = solveSppEpoch(obs.epochs[i], obs, nav, cfg, obs.approx_position_ecef);
    if (!e.solved || !e.pl.pl_computed) continue;
    const std::vector<RawRange> ranges = correctedL1Ranges(obs.epochs[i], obs, nav, e.p_ecef);
    const LiveFix f = solveLiveFix(ranges, e.position, e.t, live, true, nullptr);
    ASSERT_TRUE(f.solved) << f.note;
    EXPECT_LT((f.p_ecef - e.p_ecef).norm(), 1e-3) << formatRfc3339(e.t);
    EXPECT_EQ(f.used, e.used);
    EXPECT_EQ(f.fault_detected, e.fault_detected);
    EXPECT_NEAR(f.test_statistic, e.test_statistic, 1e-3);
    // (a 5-satellite epoch has PLs of ~100 km: there, 1e-8 of the PL)
    EXPECT_NEAR(f.pl.hpl_m, e.pl.hpl_m, 1e-3 + 1e-8 * e.pl.hpl_m);
    EXPECT_NEAR(f.pl.vpl_m, e.pl.vpl_m, 1e-3 + 1e-8 * e.pl.vpl_m);
    EXPECT_NEAR(f.clock_m, e.clock_m, 1e-3);
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

TEST(Spp, EpochWithTooFewSatellitesIsReportedNotCrashed) {
  ObservationData obs = loadRinexObs(test::dataPath("gnss/30400920.05o"));
  const NavigationData nav = loadRinexNav(test::dataPath("gnss/30400920.05n"));
  obs.epochs.resize(1);
  obs.epochs[0].sats.resize(3);
  const auto sol = solveSpp(obs, nav, SppConfig{});
  ASSERT_EQ(sol.size(), 1u);
  EXPECT_FALSE(sol[0].pl.pl_computed);
  EXPECT_FALSE(sol[0].note.empty());
}

}  // namespace
}  // namespace skylane::integrity

namespace skylane::integrity {
namespace {

TEST(SppAraim, SolutionSeparationDetectsAndExcludesAFiftyMetreBias) {
  const ObservationData obs = loadRinexObs(test::dataPath("rinex3/base_20240624_MO.rnx"));
  const NavigationData nav = loadRinexNav(test::dataPath("rinex3/base_20240624_MN.rnx"));
  SppConfig cfg;
  cfg.method = IntegrityMethod::kAraim;
  const auto clean = solveSpp(obs, nav, cfg);
  for (const auto& e : clean) {
    ASSERT_TRUE(e.solved) << e.note;
    EXPECT_TRUE(e.pl.pl_computed) << e.note;
    EXPECT_FALSE(e.fault_detected) << formatRfc3339(e.t) << " ratio " << e.test_statistic;
    EXPECT_GT(e.pl.fault_modes, 10);
  }
  const SatId e11{Constellation::kGalileo, 11};
  cfg.injected_bias_m[e11] = 50.0;
  const maps::LocalFrame f(maps::ecefToGeodetic(*obs.approx_position_ecef));
  for (const auto& e : solveSpp(obs, nav, cfg)) {
    ASSERT_TRUE(e.solved);
    EXPECT_TRUE(e.fault_detected) << formatRfc3339(e.t);
    EXPECT_EQ(e.excluded, std::vector<SatId>{e11}) << formatRfc3339(e.t);
    EXPECT_LE(e.test_statistic, 1.0);
    const Eigen::Vector3d d = f.ecefToEnu(e.p_ecef);
    EXPECT_LT(std::hypot(d.x(), d.y()), 3.0);
  }
}

}  // namespace
}  // namespace skylane::integrity
