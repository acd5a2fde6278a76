#include "integrity/raim/raim.hpp"

#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "integrity/stats.hpp"
#include "tests/test_util.hpp"

#include <cmath>
#include <random>

namespace skylane::integrity {
namespace {

// --- Independent computations for Brown's table (closed forms for even degrees of freedom) ---

/// P(χ²_k > x) for even k: e^{−x/2} Σ_{j<k/2} (x/2)^j / j!.
double chiSquareTailEven(int k, double x) {
  double term = 1.0, sum = 0.0;
  for (int j = 0; j < k / 2; ++j) {
    if (j > 0) term *= (x / 2) / j;
    sum += term;
  }
  return std::exp(-x / 2) * sum;
}

/// Non-central χ² CDF as a Poisson mixture of central ones (even k): Σ_j Pois(j; λ/2)·(1 − tail_{k+2j}).
double nonCentralCdfEven(int k, double lambda, double x) {
  double p = 0.0, w = std::exp(-lambda / 2);
  for (int j = 0; j < 400; ++j) {
    if (j > 0) w *= (lambda / 2) / j;
    p += w * (1.0 - chiSquareTailEven(k + 2 * j, x));
  }
  return p;
}

/// Bisection on a decreasing function.
double solveDecreasing(const std::function<double(double)>& f, double target, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(RaimThresholds, BrownTableEndpointsForPfa1e6Pmd1e3) {
  // Brown & Chin (1998): n = 6 … 14 satellites, 4 unknowns.
  const RaimThresholds t6 = raimThresholds(6 - 4, 1e-6, 1e-3);
  const RaimThresholds t14 = raimThresholds(14 - 4, 1e-6, 1e-3);
  EXPECT_NEAR(t6.threshold, 5.2565, 5e-5);
  EXPECT_NEAR(t14.threshold, 6.8457, 5e-5);
  EXPECT_NEAR(t6.p_bias, 8.2713, 5e-5);
  EXPECT_NEAR(t14.p_bias, 9.3746, 5e-5);
}

TEST(RaimThresholds, EveryRowMatchesAnIndependentClosedFormAndGrowsWithN) {
  double prev_t = 0, prev_p = 0;
  for (int n = 6; n <= 14; ++n) {
    const RaimThresholds t = raimThresholds(n - 4, 1e-6, 1e-3);
    EXPECT_GT(t.threshold, prev_t) << n;
    EXPECT_GT(t.p_bias, prev_p) << n;
    prev_t = t.threshold;
    prev_p = t.p_bias;
    const int k = n - 4;
    if (k % 2 != 0) continue;
    const double x = solveDecreasing([&](double v) { return chiSquareTailEven(k, v); }, 1e-6, 0.0, 200.0);
    EXPECT_NEAR(t.threshold, std::sqrt(x), 1e-6) << n;
    const double lam = solveDecreasing([&](double l) { return nonCentralCdfEven(k, l, x); }, 1e-3, 0.0, 400.0);
    EXPECT_NEAR(t.p_bias, std::sqrt(lam), 1e-6) << n;
  }
}

TEST(RaimThresholds, InvalidArgumentsThrowWithMessage) {
  const std::string msg = test::messageOf<std::invalid_argument>([] { (void)raimThresholds(0, 1e-6, 1e-3); });
  EXPECT_NE(msg.find("degree of freedom"), std::string::npos) << msg;
  EXPECT_THROW((void)raimThresholds(2, 0.0, 1e-3), std::invalid_argument);
  EXPECT_THROW((void)raimThresholds(2, 1e-6, 1.0), std::invalid_argument);
}

// --- Geometries -----------------------------------------------------------------------------

std::vector<SatLook> ring(int n, double el_deg, Constellation c = Constellation::kGps, double az0 = 0) {
  std::vector<SatLook> out;
  for (int i = 0; i < n; ++i) {
    out.push_back({{c, i + 1}, {maps::deg2rad(az0 + 360.0 * i / n), maps::deg2rad(el_deg)}});
  }
  return out;
}

std::vector<SatLook> typicalSky() {
  std::vector<SatLook> s = ring(6, 25.0);
  for (auto& l : ring(3, 60.0, Constellation::kGps, 30)) {
    l.sat.prn += 10;
    s.push_back(l);
  }
  s.push_back({{Constellation::kGps, 30}, {0.0, maps::deg2rad(89.0)}});
  return s;
}

TEST(RaimPl, TooFewSatellitesIsNotAvailableNeverNaN) {
  const ErrorModel m;
  for (int n = 0; n <= 4; ++n) {
    const RaimPl pl = raimProtectionLevels(buildGeometry(ring(n, 30.0), m, 9.0), RaimConfig{});
    EXPECT_FALSE(pl.available) << n;
    EXPECT_NE(pl.reason.find("too few satellites"), std::string::npos) << pl.reason;
    EXPECT_FALSE(std::isnan(pl.hpl_m));
  }
}

TEST(RaimPl, SingularGeometryIsNotAvailable) {
  // Five satellites at the same place in the sky: the normal matrix is singular.
  std::vector<SatLook> same;
  for (int i = 1; i <= 5; ++i) same.push_back({{Constellation::kGps, i}, {1.0, 0.7}});
  const RaimPl pl = raimProtectionLevels(buildGeometry(same, ErrorModel{}, 9.0), RaimConfig{});
  EXPECT_FALSE(pl.available);
  EXPECT_NE(pl.reason.find("singular"), std::string::npos) << pl.reason;
}

TEST(RaimPl, SlopesMatchAFiniteDifferenceOfTheEstimator) {
  // A bias b on satellite i moves the WLS estimate by S_{:,i}·b and the statistic by b·√M_ii.
  const Geometry g = buildGeometry(typicalSky(), ErrorModel{}, 9.0);
  const RaimPl pl = raimProtectionLevels(g, RaimConfig{});
  ASSERT_TRUE(pl.available);
  const WlsSolution w = solveWls(g.G, g.sigma_int);
  const Eigen::VectorXd wt = g.sigma_int.array().square().inverse();
  for (int i = 0; i < g.numSats(); ++i) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(g.numSats());
    y[i] = 1.0;  // 1 m bias, no noise
    const Eigen::VectorXd dx = w.S * y;
    const Eigen::VectorXd r = y - g.G * dx;
    const double stat = std::sqrt(r.dot(wt.asDiagonal() * r));
    EXPECT_NEAR(pl.hslope[i], std::hypot(dx[0], dx[1]) / stat, 1e-9);
    EXPECT_NEAR(pl.vslope[i], std::abs(dx[2]) / stat, 1e-9);
  }
}

TEST(RaimPl, ProtectionLevelsAreInvariantUnderRotatingTheSky) {
  // Frame invariance: rotating every azimuth leaves HPL (a radius) and VPL unchanged.
  const ErrorModel m;
  const RaimPl ref = raimProtectionLevels(buildGeometry(typicalSky(), m, 9.0), RaimConfig{});
  for (double rot : {17.0, 90.0, 203.5}) {
    auto sky = typicalSky();
    for (auto& s : sky) s.look.azimuth_rad += maps::deg2rad(rot);
    const RaimPl pl = raimProtectionLevels(buildGeometry(sky, m, 9.0), RaimConfig{});
    EXPECT_NEAR(pl.hpl_m, ref.hpl_m, 1e-9 * ref.hpl_m) << rot;
    EXPECT_NEAR(pl.vpl_m, ref.vpl_m, 1e-9 * ref.vpl_m) << rot;
  }
}

TEST(RaimPl, RemovingASatelliteNeverShrinksTheFaultFreeSigma) {
  const auto recs = loadAlmanac(test::dataPath("gnss/alm01jan2020.txt"));
  OrbitSource orbits;
  orbits.addAlmanac(recs);
  const Eigen::Vector3d site = maps::geodeticToEcef({maps::deg2rad(35.13), maps::deg2rad(139.62), 80});
  const ErrorModel m;
  int checked = 0;
  for (double t = 0; t < 86400; t += 1800) {
    std::vector<SatLook> looks;
    for (const auto& v : orbits.visible(site, GpsTime{2086, 3 * 86400 + t}, maps::deg2rad(5))) looks.push_back({v.sat, v.look});
    const Geometry g = buildGeometry(looks, m, 9.0);
    const WlsSolution all = solveWls(g.G, g.sigma_int);
    ASSERT_TRUE(all.ok);
    for (int i = 0; i < g.numSats(); ++i) {
      const Geometry h = g.without(i);
      const WlsSolution sub = solveWls(h.G, h.sigma_int);
      if (!sub.ok) continue;
      EXPECT_GE(sub.P(2, 2), all.P(2, 2) * (1 - 1e-12));
      EXPECT_GE(sub.P(0, 0) + sub.P(1, 1), (all.P(0, 0) + all.P(1, 1)) * (1 - 1e-12));
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(RaimPl, ALoneSatelliteOfAnotherConstellationChangesNothing) {
  // It only fixes its own clock: the same PLs as without it (the redundancy is unchanged too).
  const ErrorModel m;
  const RaimPl gps = raimProtectionLevels(buildGeometry(typicalSky(), m, 9.0), RaimConfig{});
  auto sky = typicalSky();
  sky.push_back({{Constellation::kGalileo, 5}, {1.0, 0.6}});
  const RaimPl mixed = raimProtectionLevels(buildGeometry(sky, m, 9.0), RaimConfig{});
  ASSERT_TRUE(mixed.available) << mixed.reason;
  EXPECT_NEAR(mixed.hpl_m, gps.hpl_m, 1e-9);
  EXPECT_NEAR(mixed.vpl_m, gps.vpl_m, 1e-9);
}

TEST(RaimPl, BrownFormulaIsSlopeTimesPbias) {
  const Geometry g = buildGeometry(typicalSky(), ErrorModel{}, 9.0);
  RaimConfig cfg;
  cfg.formula = RaimPlFormula::kSlopePbias;
  const RaimPl pl = raimProtectionLevels(g, cfg);
  ASSERT_TRUE(pl.available);
  const double pb = raimThresholds(g.numSats() - 4, cfg.pfa, cfg.pmd).p_bias;
  EXPECT_NEAR(pl.hpl_m, std::max(pl.hslope.maxCoeff() * pb, normalTailInverse(cfg.phmi_hor / 2) * pl.sigma_h_m), 1e-9);
  EXPECT_NEAR(pl.vpl_m, std::max(pl.vslope.maxCoeff() * pb, normalTailInverse(cfg.phmi_vert / 2) * pl.sigma_v_m), 1e-9);
}

TEST(RaimFde, FiftyMetreBiasIsDetectedAndTheRightSatelliteExcluded) {
  const Geometry g = buildGeometry(typicalSky(), ErrorModel{}, 9.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  int correct = 0;
  const int trials = 200;
  for (int k = 0; k < trials; ++k) {
    const int bad = k % g.numSats();
    Eigen::VectorXd y(g.numSats());
    for (int i = 0; i < g.numSats(); ++i) y[i] = g.sigma_int[i] * n01(rng);
    y[bad] += 50.0;
    const RaimFdeResult r = raimFde(g, y, RaimConfig{});
    ASSERT_TRUE(r.solution_ok);
    EXPECT_TRUE(r.fault_detected);
    if (r.fault_excluded && r.excluded == std::vector<int>{bad}) ++correct;
  }
  EXPECT_GE(correct, trials * 95 / 100);
}

TEST(RaimFde, NoFaultNoExclusion) {
  const Geometry g = buildGeometry(typicalSky(), ErrorModel{}, 9.0);
  const RaimFdeResult r = raimFde(g, Eigen::VectorXd::Zero(g.numSats()), RaimConfig{});
  EXPECT_FALSE(r.fault_detected);
  EXPECT_TRUE(r.excluded.empty());
  EXPECT_TRUE(r.pl.available);
  EXPECT_NEAR(r.test_statistic, 0.0, 1e-9);
}

}  // namespace
}  // namespace skylane::integrity
