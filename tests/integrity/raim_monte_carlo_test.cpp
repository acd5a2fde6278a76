// Integrity is safety: the RAIM protection levels must bound the position error with the
// stated probabilities. These Monte Carlo runs use probabilities large enough to be measured
// (P_fa 1e-3, P_md 1e-2, PHMI 1e-3) on real almanac geometries and check:
//  * fault-free: false-alert rate ≈ P_fa; P(|error| > PL) ≤ PHMI;
//  * faulted: for every satellite and every bias size (a sweep through the undetectable and
//    detectable region), P(error > PL and not detected) ≤ P_md.
#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "integrity/raim/raim.hpp"

#include "tests/test_util.hpp"

#include <cmath>
#include <random>

namespace skylane::integrity {
namespace {

/// Binomial confidence margin: 4 standard deviations of the estimated rate.
double margin(double p, int n) { return 4.0 * std::sqrt(p * (1 - p) / n) + 4.0 / n; }

RaimConfig testableConfig(RaimPlFormula f) {
  RaimConfig c;
  c.pfa = 1e-3;
  c.pmd = 1e-2;
  c.phmi_hor = 1e-3;
  c.phmi_vert = 1e-3;
  c.formula = f;
  return c;
}

std::vector<Geometry> almanacGeometries() {
  OrbitSource orbits;
  orbits.addAlmanac(loadAlmanac(test::dataPath("gnss/alm01jan2020.txt")));
  const Eigen::Vector3d site = maps::geodeticToEcef({maps::deg2rad(35.13), maps::deg2rad(139.62), 80});
  std::vector<Geometry> out;
  for (double t : {0.0, 15600.0, 40000.0}) {  // 15600 s is the VPL peak of the example day
    std::vector<SatLook> looks;
    for (const auto& v : orbits.visible(site, GpsTime{2086, 3 * 86400 + t}, maps::deg2rad(5))) looks.push_back({v.sat, v.look});
    ErrorModel m;
    out.push_back(buildGeometry(looks, m, 9.0));
  }
  return out;
}

struct Rates {
  double false_alert = 0, ff_exceed_h = 0, ff_exceed_v = 0, worst_hmi_h = 0, worst_hmi_v = 0;
};

Rates simulate(const Geometry& g, const RaimConfig& cfg, int n_ff, int n_fault, unsigned seed) {
  const RaimPl pl = raimProtectionLevels(g, cfg);
  EXPECT_TRUE(pl.available);
  const WlsSolution w = solveWls(g.G, g.sigma_int);
  const Eigen::VectorXd wt = g.sigma_int.array().square().inverse();
  const double t2 = pl.thresholds.threshold * pl.thresholds.threshold;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  const int n = g.numSats();
  Eigen::VectorXd y(n);
  auto draw = [&](int fault_sat, double bias, bool& detected, double& eh, double& ev) {
    for (int i = 0; i < n; ++i) y[i] = g.sigma_int[i] * n01(rng);
    if (fault_sat >= 0) y[fault_sat] += bias;
    const Eigen::VectorXd dx = w.S * y;
    const Eigen::VectorXd r = y - g.G * dx;
    detected = r.dot(wt.asDiagonal() * r) > t2;
    eh = std::hypot(dx[0], dx[1]);
    ev = std::abs(dx[2]);
  };
  Rates out;
  bool det = false;
  double eh = 0, ev = 0;
  int fa = 0, xh = 0, xv = 0;
  for (int k = 0; k < n_ff; ++k) {
    draw(-1, 0.0, det, eh, ev);
    fa += det;
    xh += eh > pl.hpl_m;
    xv += ev > pl.vpl_m;
  }
  out.false_alert = double(fa) / n_ff;
  out.ff_exceed_h = double(xh) / n_ff;
  out.ff_exceed_v = double(xv) / n_ff;
  for (int i = 0; i < n; ++i) {
    const double m_ii = wt[i] - wt[i] * wt[i] * g.G.row(i).dot(w.P * g.G.row(i).transpose());
    for (int step = 1; step <= 16; ++step) {
      // Non-centrality from 0.1 to 1.6 × p_bias: through the worst case for every satellite.
      const double bias = 0.1 * step * pl.thresholds.p_bias / std::sqrt(m_ii);
      int hmi_h = 0, hmi_v = 0;
      for (int k = 0; k < n_fault; ++k) {
        draw(i, bias, det, eh, ev);
        hmi_h += !det && eh > pl.hpl_m;
        hmi_v += !det && ev > pl.vpl_m;
      }
      out.worst_hmi_h = std::max(out.worst_hmi_h, double(hmi_h) / n_fault);
      out.worst_hmi_v = std::max(out.worst_hmi_v, double(hmi_v) / n_fault);
    }
  }
  return out;
}

TEST(RaimMonteCarlo, DefaultLevelsBoundFaultFreeAndFaultedErrorsForEveryBiasSize) {
  const RaimConfig cfg = testableConfig(RaimPlFormula::kSlopePbiasPlusNoise);
  const int n_ff = 200000, n_fault = 4000;
  unsigned seed = 1;
  for (const Geometry& g : almanacGeometries()) {
    const Rates r = simulate(g, cfg, n_ff, n_fault, seed++);
    RecordProperty("worst_hmi_v", std::to_string(r.worst_hmi_v));
    EXPECT_NEAR(r.false_alert, cfg.pfa, margin(cfg.pfa, n_ff)) << g.numSats() << " satellites";
    EXPECT_LE(r.ff_exceed_h, cfg.phmi_hor + margin(cfg.phmi_hor, n_ff));
    EXPECT_LE(r.ff_exceed_v, cfg.phmi_vert + margin(cfg.phmi_vert, n_ff));
    EXPECT_LE(r.worst_hmi_h, cfg.pmd + margin(cfg.pmd, n_fault)) << g.numSats() << " satellites";
    EXPECT_LE(r.worst_hmi_v, cfg.pmd + margin(cfg.pmd, n_fault)) << g.numSats() << " satellites";
    std::printf("pbias+noise n=%d: Pfa %.2e, ff exceed H %.1e V %.1e, worst P(HMI|fault) H %.4f V %.4f (Pmd %.0e)\n",
                g.numSats(), r.false_alert, r.ff_exceed_h, r.ff_exceed_v, r.worst_hmi_h, r.worst_hmi_v, cfg.pmd);
  }
}

TEST(RaimMonteCarlo, BrownLevelsAreMeasuredAndReported) {
  // Brown's slope × p_bias ignores the noise in the position along the fault direction; its
  // worst-case missed-detection-and-exceed rate is measured here and must stay within 5 × P_md
  // (the classic result is ≈ P_md/2 … P_md depending on the slope spread).
  const RaimConfig cfg = testableConfig(RaimPlFormula::kSlopePbias);
  unsigned seed = 100;
  for (const Geometry& g : almanacGeometries()) {
    const Rates r = simulate(g, cfg, 20000, 4000, seed++);
    std::printf("Brown n=%d: worst P(HMI|fault) H %.4f V %.4f (Pmd %.0e)\n", g.numSats(), r.worst_hmi_h, r.worst_hmi_v, cfg.pmd);
    EXPECT_LE(r.worst_hmi_h, 5 * cfg.pmd);
    EXPECT_LE(r.worst_hmi_v, 5 * cfg.pmd);
  }
}

}  // namespace
}  // namespace skylane::integrity
