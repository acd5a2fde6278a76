// Protection levels after fault exclusion (docs/method.md §3.2a, §4.3) proved by Monte Carlo
// with injected faults. Every epoch draws Gaussian range errors with the integrity σ's, adds a
// bias on one satellite (a sweep over satellites and bias sizes through the undetected, the
// ambiguous and the cleanly excluded region), runs the method's FDE and counts misleading
// information (MI): the outcome gives a PL (no fault detected, or one excluded) and the position
// error exceeds it. Probabilities are large enough to be measured. Each cell's MI rate is judged
// by its Clopper–Pearson bounds at a family-wise 1e-3 (Bonferroni over the cells), so a correct
// PL fails the test with probability below 1e-3.
//  * RAIM FDE: the claim is P(MI | fault, any bias) ≤ P_md, over all outcomes together.
//  * ARAIM FDE: the claim is the total vertical integrity risk of the single-satellite fault
//    modes, Σ_i P_sat,i · max_b P(MI | fault on i, b) + P(fault-free) · P(MI | fault-free),
//    within the vertical budget after the unmonitored share.
// Both are run with the allocated PL (the default) and with the plain PL of the remaining
// geometry, on the same draws, and both sets of figures are printed.
#include "integrity/araim/exclusion.hpp"
#include "integrity/araim/fde.hpp"
#include "tests/integrity/araim_example.hpp"
#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "integrity/raim/raim.hpp"

#include "tests/test_util.hpp"

#include <boost/math/special_functions/beta.hpp>

#include <cmath>
#include <cstdio>
#include <random>

namespace skylane::integrity {
namespace {

/// Family-wise probability that a correct PL fails a test here.
constexpr double kFamilyAlpha = 1e-3;

/// Clopper–Pearson one-sided bounds of a binomial rate with k successes in n at level alpha.
double lowerBound(int k, int n, double alpha) {
  return k == 0 ? 0.0 : boost::math::ibeta_inv(static_cast<double>(k), static_cast<double>(n - k + 1), alpha);
}
double upperBound(int k, int n, double alpha) {
  return k >= n ? 1.0 : boost::math::ibeta_inv(static_cast<double>(k + 1), static_cast<double>(n - k), 1.0 - alpha);
}

std::vector<Geometry> almanacGeometries() {
  OrbitSource orbits;
  orbits.addAlmanac(loadAlmanac(test::dataPath("gnss/alm01jan2020.txt")));
  const Eigen::Vector3d site = maps::geodeticToEcef({maps::deg2rad(35.13), maps::deg2rad(139.62), 80});
  std::vector<Geometry> out;
  for (double t : {0.0, 15600.0, 40000.0}) {
    std::vector<SatLook> looks;
    for (const auto& v : orbits.visible(site, GpsTime{2086, 3 * 86400 + t}, maps::deg2rad(5))) looks.push_back({v.sat, v.look});
    out.push_back(buildGeometry(looks, ErrorModel{}, 9.0));
  }
  return out;
}

/// MI counts of one (satellite, bias) cell for the allocated and the plain PL.
struct Cell {
  int n = 0, mi_allocated = 0, mi_plain = 0, excluded = 0, wrong = 0;
};

// ---------------------------------------------------------------- RAIM FDE

RaimConfig measurableRaim(ExclusionPl pl) {
  RaimConfig c;
  c.pfa = 1e-3;
  c.pmd = 1e-2;
  c.phmi_hor = 1e-3;
  c.phmi_vert = 1e-3;
  c.exclusion_pl = pl;
  return c;
}

bool misleading(const RaimFdeResult& r) {
  if (!r.solution_ok || !r.pl.available || (r.fault_detected && !r.fault_excluded)) return false;
  return std::hypot(r.dx[0], r.dx[1]) > r.pl.hpl_m || std::abs(r.dx[2]) > r.pl.vpl_m;
}

TEST(ExclusionMonteCarlo, RaimPlAfterExclusionBoundsTheErrorAtTheStatedRate) {
  // GIVEN three almanac skies, P_fa 1e-3, P_md 1e-2, one bias per epoch on satellite i of
  // non-centrality 0.2 … 2.4 × p_bias², 2,500 epochs per cell
  constexpr int kPerCell = 2500;
  constexpr int kSteps = 12;
  const RaimConfig allocated = measurableRaim(ExclusionPl::kAllocated);
  const RaimConfig plain = measurableRaim(ExclusionPl::kRemainingGeometry);
  std::vector<Cell> cells;
  std::mt19937_64 rng(18);
  std::normal_distribution<double> n01;
  for (const Geometry& g : almanacGeometries()) {
    const RaimPl pl = raimProtectionLevels(g, allocated);
    ASSERT_TRUE(pl.available) << pl.reason;
    const WlsSolution w = solveWls(g.G, g.sigma_int);
    const int n = g.numSats();
    for (int i = 0; i < n; ++i) {
      const double wi = 1.0 / (g.sigma_int[i] * g.sigma_int[i]);
      const double m_ii = wi - wi * wi * g.G.row(i).dot(w.P * g.G.row(i).transpose());
      for (int step = 1; step <= kSteps; ++step) {
        const double bias = std::sqrt(0.2 * step) * pl.thresholds.p_bias / std::sqrt(m_ii);
        Cell c;
        Eigen::VectorXd y(n);
        // WHEN both FDE variants solve the same draws
        for (int k = 0; k < kPerCell; ++k) {
          for (int s = 0; s < n; ++s) y[s] = g.sigma_int[s] * n01(rng);
          y[i] += bias;
          const RaimFdeResult a = raimFde(g, y, allocated);
          const RaimFdeResult p = raimFde(g, y, plain);
          ++c.n;
          c.mi_allocated += misleading(a);
          c.mi_plain += misleading(p);
          c.excluded += a.fault_excluded;
          c.wrong += a.fault_excluded && a.excluded != std::vector<int>{i};
        }
        cells.push_back(c);
      }
    }
  }
  // THEN no cell's MI rate is significantly above P_md with the allocated PL
  const double alpha = kFamilyAlpha / static_cast<double>(cells.size());
  double worst_a = 0, worst_p = 0, worst_lower_p = 0;
  int over_a = 0, over_p = 0, exclusions = 0, wrong = 0, mi_a = 0, mi_p = 0;
  for (const Cell& c : cells) {
    worst_a = std::max(worst_a, double(c.mi_allocated) / c.n);
    worst_p = std::max(worst_p, double(c.mi_plain) / c.n);
    worst_lower_p = std::max(worst_lower_p, lowerBound(c.mi_plain, c.n, alpha));
    over_a += lowerBound(c.mi_allocated, c.n, alpha) > allocated.pmd;
    over_p += lowerBound(c.mi_plain, c.n, alpha) > plain.pmd;
    exclusions += c.excluded;
    wrong += c.wrong;
    mi_a += c.mi_allocated;
    mi_p += c.mi_plain;
  }
  std::printf("RAIM FDE, %zu cells x %d epochs: %d exclusions (%d wrong); MI allocated %d (worst cell %.4f), plain %d "
              "(worst cell %.4f, its CP lower bound %.4f); P_md %.0e; cells significantly above P_md: allocated %d, "
              "plain %d\n",
              cells.size(), kPerCell, exclusions, wrong, mi_a, worst_a, mi_p, worst_p, worst_lower_p, allocated.pmd, over_a,
              over_p);
  EXPECT_GT(wrong, 0);  // the sweep reaches the region where the w-test picks the wrong satellite
  EXPECT_EQ(over_a, 0);
  EXPECT_LE(mi_a, mi_p);  // same exclusion decision (T_d from P_fa), never a smaller PL
  RecordProperty("raim_worst_mi_allocated", std::to_string(worst_a));
  RecordProperty("raim_worst_mi_plain", std::to_string(worst_p));
}

// ---------------------------------------------------------------- ARAIM FDE

/// The ADD v3.0 Appendix D example geometry with the simulated errors' own σ and no bias.
Geometry addExampleGeometry() {
  Geometry g = araim_example::addExampleGeometry();
  g.bnom = Eigen::VectorXd::Zero(10);  // no nominal bias: the simulated errors are zero-mean
  g.sigma_acc = g.sigma_int;           // the simulated errors have the integrity σ's
  return g;
}

AraimConfig measurableAraim(ExclusionPl pl) {
  AraimConfig c;
  c.requirements.phmi_vert = 1e-3;
  c.requirements.phmi_hor = 1e-3;
  c.requirements.pfa_vert = 1e-3;
  c.requirements.pfa_hor = 1e-3;
  c.requirements.p_thres = 1e-4;
  c.requirements.tol_pl_m = 1e-3;
  c.exclusion_pl = pl;
  return c;
}

bool misleadingVertical(const AraimFdeResult& r) {
  if (!r.solution_ok || !r.pl.pl_computed || (r.fault_detected && !r.fault_excluded)) return false;
  return std::abs(r.dx[2]) > r.pl.vpl_m;
}

TEST(ExclusionMonteCarlo, AraimPlAfterExclusionBoundsTheIntegrityRiskWithinTheBudget) {
  // GIVEN the ADD example sky, P_sat 1e-3, P_const 1e-4, P_HMI,V 1e-3 (ρ = 1/11: ten
  // single-satellite candidates), and one bias per epoch on satellite i of 0.25 … 2.5 × the
  // bias that moves the separation of mode {i} to its threshold T_i,U
  constexpr int kPerCell = 1200;
  constexpr int kSteps = 10;
  constexpr int kFaultFree = 20000;
  const Geometry g = addExampleGeometry();
  ErrorModel model;
  for (Constellation c : kAllConstellations) {
    model.of(c).psat = 1e-3;
    model.of(c).pconst = 1e-4;
  }
  const AraimConfig allocated = measurableAraim(ExclusionPl::kAllocated);
  const AraimConfig plain = measurableAraim(ExclusionPl::kRemainingGeometry);
  const AraimResult fd = araimProtectionLevels(g, model, allocated);
  ASSERT_TRUE(fd.pl_computed) << fd.reason;
  const Requirements& req = allocated.requirements;
  const double budget_v = req.phmi_vert * (1.0 - fd.p_not_monitored / (req.phmi_vert + req.phmi_hor));
  std::mt19937_64 rng(1804);
  std::normal_distribution<double> n01;
  const int n = g.numSats();
  Eigen::VectorXd y(n);
  auto draw = [&](int faulty, double bias, Cell& c) {
    for (int s = 0; s < n; ++s) y[s] = g.sigma_int[s] * n01(rng);
    if (faulty >= 0) y[faulty] += bias;
    // WHEN both FDE variants solve the same draw
    const AraimFdeResult a = araimFde(g, y, model, allocated);
    const AraimFdeResult p = araimFde(g, y, model, plain);
    ++c.n;
    c.mi_allocated += misleadingVertical(a);
    c.mi_plain += misleadingVertical(p);
    c.excluded += a.fault_excluded;
    c.wrong += a.fault_excluded && a.excluded != std::vector<int>{faulty};
  };
  Cell fault_free;
  for (int k = 0; k < kFaultFree; ++k) draw(-1, 0.0, fault_free);
  std::vector<std::vector<Cell>> cells(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const SubsetSolution* mode = nullptr;
    for (const SubsetSolution& s : fd.subsets) {
      if (s.removed == std::vector<int>{i}) mode = &s;
    }
    ASSERT_NE(mode, nullptr);
    const double unit = mode->threshold[2] / std::abs(fd.S0(2, i));
    for (int step = 1; step <= kSteps; ++step) {
      Cell c;
      for (int k = 0; k < kPerCell; ++k) draw(i, 0.25 * step * unit, c);
      cells[static_cast<std::size_t>(i)].push_back(c);
    }
  }
  // THEN the estimated risk Σ p_i max_b rate + P(ff)·rate_ff stays within the budget for the
  // allocated PL: its Clopper–Pearson lower bound (a correct PL fails with probability < 1e-3)
  // and, stronger, its upper bound (the risk is shown to be within the budget)
  const double alpha = kFamilyAlpha / static_cast<double>(n * kSteps + 1);
  const double p_sat = 1e-3, p_ff = 1.0 - n * p_sat;
  auto risk = [&](auto rate) {
    double r = p_ff * rate(fault_free);
    for (const std::vector<Cell>& row : cells) {
      double worst = 0.0;
      for (const Cell& c : row) worst = std::max(worst, rate(c));
      r += p_sat * worst;
    }
    return r;
  };
  const double risk_a = risk([](const Cell& c) { return double(c.mi_allocated) / c.n; });
  const double risk_p = risk([](const Cell& c) { return double(c.mi_plain) / c.n; });
  const double lower_a = risk([&](const Cell& c) { return lowerBound(c.mi_allocated, c.n, alpha); });
  const double lower_p = risk([&](const Cell& c) { return lowerBound(c.mi_plain, c.n, alpha); });
  const double upper_a = risk([&](const Cell& c) { return upperBound(c.mi_allocated, c.n, alpha); });
  int exclusions = 0, wrong = 0;
  for (const auto& row : cells) {
    for (const Cell& c : row) {
      exclusions += c.excluded;
      wrong += c.wrong;
    }
  }
  std::printf("ARAIM FDE, %d x %d cells x %d epochs + %d fault-free: %d exclusions (%d wrong); vertical risk "
              "allocated %.3e (CP %.3e … %.3e), plain %.3e (CP lower %.3e); budget %.3e; fault-free MI %d / %d\n",
              n, kSteps, kPerCell, kFaultFree, exclusions, wrong, risk_a, lower_a, upper_a, risk_p, lower_p, budget_v,
              fault_free.mi_allocated, fault_free.mi_plain);
  EXPECT_GT(wrong, 0);
  EXPECT_LE(lower_a, budget_v);
  EXPECT_LE(upper_a, budget_v);
  RecordProperty("araim_risk_allocated", std::to_string(risk_a));
  RecordProperty("araim_risk_plain", std::to_string(risk_p));
}

}  // namespace
}  // namespace skylane::integrity
