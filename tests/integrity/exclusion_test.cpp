// Protection levels after fault exclusion (docs/method.md §3.2a, §4.3): the restricted fault
// modes, the budget share ρ = 1/(N_exc + 1), and the PLs of RAIM and ARAIM FDE outcomes.
#include "integrity/araim/exclusion.hpp"
#include "integrity/araim/fde.hpp"
#include "tests/integrity/araim_example.hpp"
#include "integrity/raim/raim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <cmath>
#include <set>

namespace skylane::integrity {
namespace {

using araim_example::addExampleGeometry;
using araim_example::ismWith;

TEST(ExclusionModes, RestrictionRenumbersDropsCoveredModesAndMergesCoincidingOnes) {
  // GIVEN modes {0}, {1}, {0,1}, {2}, {1,3} on four satellites, P_nm 1e-9
  FaultModeSet all;
  all.p_not_monitored = 1e-9;
  all.n_fault_max = 2;
  all.modes = {{{0}, 1e-3, 1e-3, 1}, {{1}, 2e-3, 2e-3, 1}, {{0, 1}, 1e-6, 1e-6, 2}, {{2}, 3e-3, 3e-3, 1},
               {{1, 3}, 5e-6, 5e-6, 2}};
  // WHEN satellite 1 is excluded
  const FaultModeSet r = restrictFaultModes(all, {1});
  // THEN {1} is covered by the fault-free term, {0,1} merges into {0}, {2} → {1}, {1,3} → {2}
  ASSERT_EQ(r.modes.size(), 3u);
  EXPECT_EQ(r.modes[0].removed, std::vector<int>{0});
  EXPECT_DOUBLE_EQ(r.modes[0].prior, 1e-3 + 1e-6);
  EXPECT_EQ(r.modes[0].events, 1);
  EXPECT_EQ(r.modes[1].removed, std::vector<int>{1});
  EXPECT_DOUBLE_EQ(r.modes[1].prior, 3e-3);
  EXPECT_EQ(r.modes[2].removed, std::vector<int>{2});
  EXPECT_DOUBLE_EQ(r.modes[2].prior, 5e-6);
  EXPECT_DOUBLE_EQ(r.p_not_monitored, 1e-9);
  EXPECT_EQ(r.n_fault_max, 2);
}

TEST(ExclusionCandidates, EverySatelliteAndTheWideFaultsAboveTheBudget) {
  const Geometry g = addExampleGeometry();
  AraimConfig cfg;  // P_HMI 1e-7
  EXPECT_EQ(exclusionCandidates(g, ismWith(1e-5, 1e-4), cfg).size(), 10u);  // satellites only by default
  cfg.exclude_constellations = true;
  // P_const 1e-4 > P_HMI: both constellations are candidates (MAAST: p_const > 1e-7)
  EXPECT_EQ(exclusionCandidates(g, ismWith(1e-5, 1e-4), cfg).size(), 12u);
  EXPECT_EQ(exclusionCandidates(g, ismWith(1e-5, 1e-4), cfg)[10], (std::vector<int>{0, 1, 2, 3, 4}));
  // P_const 1e-8: only the satellites
  EXPECT_EQ(exclusionCandidates(g, ismWith(1e-5, 1e-8), cfg).size(), 10u);
  EXPECT_DOUBLE_EQ(exclusionBudgetShare(12), 1.0 / 13.0);
  // and the prediction then has no PL: after Galileo is excluded a GPS fault (1e-4) is unmonitorable
  const AraimResult wide = araimFdeProtectionLevels(g, ismWith(1e-5, 1e-4), cfg);
  EXPECT_FALSE(wide.pl_computed);
  EXPECT_NE(wide.reason.find("an exclusion outcome has no protection level"), std::string::npos) << wide.reason;
}

TEST(ExclusionPl, NoExclusionAtFullShareIsTheDetectionOnlyPl) {
  const Geometry g = addExampleGeometry();
  const ErrorModel model = ismWith(1e-5, 1e-4);
  const AraimConfig cfg;
  const AraimResult fd = araimProtectionLevels(g, model, cfg);
  const AraimResult same = araimLevelsAfterExclusion(g, araimFaultModes(g, model, cfg), {}, cfg, 1.0);
  ASSERT_TRUE(same.pl_computed);
  EXPECT_DOUBLE_EQ(same.vpl_m, fd.vpl_m);
  EXPECT_DOUBLE_EQ(same.hpl_m, fd.hpl_m);
  EXPECT_EQ(same.fault_modes, fd.fault_modes);
}

// GIVEN the ADD example, P_sat 1e-5, P_const 1e-4 (10 candidates, ρ = 1/11)
// WHEN satellite k is excluded
// THEN the outcome's modes are the all-in-view modes without k's satellite, its VPL solves the
// risk equation at ρ·𝓑_V, and it is above the plain PL of the remaining geometry
TEST(ExclusionPl, AraimOutcomeSolvesTheRestrictedRiskEquationAtItsShare) {
  const Geometry g = addExampleGeometry();
  const ErrorModel model = ismWith(1e-5, 1e-4);
  AraimConfig cfg;
  cfg.requirements.tol_pl_m = 1e-6;
  const FaultModeSet modes = araimFaultModes(g, model, cfg);
  const double rho = exclusionBudgetShare(exclusionCandidates(g, model, cfg).size());
  for (int k : {0, 5, 9}) {
    const AraimResult r = araimLevelsAfterExclusion(g, modes, {k}, cfg, rho);
    ASSERT_TRUE(r.pl_computed) << r.reason;
    EXPECT_DOUBLE_EQ(r.budget_share, 1.0 / 11.0);
    // the modes, mapped back to the all-in-view numbering and with k added back
    std::set<std::vector<int>> expected, got;
    for (const FaultMode& m : modes.modes) {
      std::vector<int> with_k = m.removed;
      if (std::find(with_k.begin(), with_k.end(), k) == with_k.end()) with_k.push_back(k);
      std::sort(with_k.begin(), with_k.end());
      if (with_k != std::vector<int>{k}) expected.insert(with_k);
    }
    for (const SubsetSolution& s : r.subsets) {
      std::vector<int> back{k};
      for (int i : s.removed) back.push_back(i < k ? i : i + 1);
      std::sort(back.begin(), back.end());
      got.insert(back);
    }
    EXPECT_EQ(got, expected) << "excluded " << k;
    // the vertical risk at the VPL is the budget share (within the solver's tolerance)
    std::vector<RiskTerm> terms{{2.0, 0.0, r.bias0[2], r.sigma0[2]}};
    for (const SubsetSolution& s : r.subsets) terms.push_back({s.prior, s.threshold[2], s.bias[2], s.sigma[2]});
    const Requirements& q = cfg.requirements;
    const double budget = rho * q.phmi_vert * (1.0 - r.p_not_monitored / (q.phmi_vert + q.phmi_hor));
    EXPECT_LE(integrityRisk(terms, r.vpl_m), budget);
    EXPECT_GT(integrityRisk(terms, r.vpl_m - 2e-6), budget);
    const AraimResult plain = araimProtectionLevels(g.without(k), model, cfg);
    EXPECT_GT(r.vpl_m, plain.vpl_m) << "excluded " << k;
  }
}

TEST(ExclusionPl, AraimFdeExcludesTheBiasedSatelliteAndReportsTheOutcomePl) {
  const Geometry g = addExampleGeometry();
  const ErrorModel model = ismWith(1e-5, 1e-4);
  const AraimConfig cfg;  // ExclusionPl::kAllocated
  Eigen::VectorXd x_true(5);
  x_true << 3.0, -2.0, 5.0, 12.0, -7.0;
  const Eigen::VectorXd clean = g.G * x_true;
  const FaultModeSet modes = araimFaultModes(g, model, cfg);
  for (int faulty : {0, 3, 6, 9}) {
    Eigen::VectorXd y = clean;
    y[faulty] += 60.0;
    const AraimFdeResult r = araimFde(g, y, model, cfg);
    ASSERT_TRUE(r.fault_excluded) << "satellite " << faulty;
    ASSERT_EQ(r.excluded, std::vector<int>{faulty});
    EXPECT_EQ(r.exclusion_candidates, 10);
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(r.dx[q], x_true[q], 1e-6);
    const AraimResult outcome = araimLevelsAfterExclusion(g, modes, {faulty}, cfg, 1.0 / 11.0);
    EXPECT_DOUBLE_EQ(r.pl.vpl_m, outcome.vpl_m);
    EXPECT_DOUBLE_EQ(r.pl.hpl_m, outcome.hpl_m);
    EXPECT_LE(r.max_test_ratio, 1.0);
  }
  // no fault: the no-exclusion outcome, also at ρ = 1/11, above the detection-only PL
  const AraimFdeResult quiet = araimFde(g, clean, model, cfg);
  EXPECT_FALSE(quiet.fault_detected);
  EXPECT_DOUBLE_EQ(quiet.pl.budget_share, 1.0 / 11.0);
  EXPECT_GT(quiet.pl.vpl_m, araimProtectionLevels(g, model, cfg).vpl_m);
}

TEST(ExclusionPl, AraimPredictionIsTheMaximumOverTheOutcomes) {
  const Geometry g = addExampleGeometry();
  const ErrorModel model = ismWith(1e-5, 1e-4);
  const AraimConfig cfg;
  const AraimResult fde = araimFdeProtectionLevels(g, model, cfg);
  ASSERT_TRUE(fde.pl_computed) << fde.reason;
  const FaultModeSet modes = araimFaultModes(g, model, cfg);
  const double rho = 1.0 / 11.0;
  double vpl = araimLevelsOverModes(g, modes, cfg, rho).vpl_m, hpl = araimLevelsOverModes(g, modes, cfg, rho).hpl_m;
  for (const std::vector<int>& k : exclusionCandidates(g, model, cfg)) {
    const AraimResult r = araimLevelsAfterExclusion(g, modes, k, cfg, rho);
    ASSERT_TRUE(r.pl_computed) << r.reason;
    vpl = std::max(vpl, r.vpl_m);
    hpl = std::max(hpl, r.hpl_m);
  }
  EXPECT_DOUBLE_EQ(fde.vpl_m, vpl);
  EXPECT_DOUBLE_EQ(fde.hpl_m, hpl);
  EXPECT_GT(fde.vpl_m, araimProtectionLevels(g, model, cfg).vpl_m);
}

TEST(ExclusionPl, RaimCandidatesAreTheSetsThatLeaveRedundancy) {
  EXPECT_EQ(raimExclusionCandidates(10, 4, 1), 10);
  EXPECT_EQ(raimExclusionCandidates(10, 4, 2), 10 + 45);
  EXPECT_EQ(raimExclusionCandidates(6, 4, 2), 6);  // two out leaves no redundancy
  EXPECT_EQ(raimExclusionCandidates(5, 4, 1), 0);
}

TEST(ExclusionPl, RaimFdeOutcomeHasItsShareOfPmdAndPhmi) {
  const Geometry g = addExampleGeometry();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(g.numSats());
  y[6] = 80.0;
  const RaimConfig cfg;  // ExclusionPl::kAllocated, one exclusion: N_exc = 10
  const RaimFdeResult r = raimFde(g, y, cfg);
  ASSERT_TRUE(r.fault_excluded);
  ASSERT_EQ(r.excluded, std::vector<int>{6});
  EXPECT_EQ(r.exclusion_candidates, 10);
  EXPECT_DOUBLE_EQ(r.budget_share, 1.0 / 11.0);
  const RaimPl outcome = raimProtectionLevels(g.without(6), outcomeConfig(cfg, 1.0 / 11.0));
  EXPECT_DOUBLE_EQ(r.pl.vpl_m, outcome.vpl_m);
  EXPECT_DOUBLE_EQ(r.pl.hpl_m, outcome.hpl_m);
  RaimConfig plain = cfg;
  plain.exclusion_pl = ExclusionPl::kRemainingGeometry;
  const RaimFdeResult p = raimFde(g, y, plain);
  EXPECT_DOUBLE_EQ(p.pl.vpl_m, raimProtectionLevels(g.without(6), cfg).vpl_m);
  EXPECT_GT(r.pl.vpl_m, p.pl.vpl_m);
  // p_bias at ρ·P_md: the threshold (from P_fa) is the same
  EXPECT_DOUBLE_EQ(r.pl.thresholds.threshold, p.pl.thresholds.threshold);
  EXPECT_GT(r.pl.thresholds.p_bias, p.pl.thresholds.p_bias);
}

TEST(ExclusionPl, RaimPredictionIsTheMaximumOverTheOutcomes) {
  const Geometry g = addExampleGeometry();  // 10 satellites, 5 states
  for (int max_exclusions : {1, 2}) {
    RaimConfig cfg;
    cfg.max_exclusions = max_exclusions;
    const RaimPl fde = raimFdeProtectionLevels(g, cfg);
    ASSERT_TRUE(fde.available) << fde.reason;
    // By hand: ρ = 1/(N_exc + 1) of P_md and P_HMI; every single exclusion, and every pair.
    const double rho = 1.0 / (max_exclusions == 1 ? 11.0 : 56.0);
    RaimConfig outcome = cfg;
    outcome.pmd = cfg.pmd * rho;
    outcome.phmi_hor = cfg.phmi_hor * rho;
    outcome.phmi_vert = cfg.phmi_vert * rho;
    double hpl = raimProtectionLevels(g, outcome).hpl_m, vpl = raimProtectionLevels(g, outcome).vpl_m;
    for (int i = 0; i < g.numSats(); ++i) {
      const RaimPl one = raimProtectionLevels(g.without(i), outcome);
      hpl = std::max(hpl, one.hpl_m);
      vpl = std::max(vpl, one.vpl_m);
      for (int j = i + 1; j < g.numSats() && max_exclusions == 2; ++j) {
        const RaimPl two = raimProtectionLevels(g.without(j).without(i), outcome);
        hpl = std::max(hpl, two.hpl_m);
        vpl = std::max(vpl, two.vpl_m);
      }
    }
    EXPECT_DOUBLE_EQ(fde.hpl_m, hpl) << max_exclusions;
    EXPECT_DOUBLE_EQ(fde.vpl_m, vpl) << max_exclusions;
    EXPECT_GT(fde.vpl_m, raimProtectionLevels(g, cfg).vpl_m);
  }
  // The plain rule: every outcome with the whole budget.
  RaimConfig plain;
  plain.exclusion_pl = ExclusionPl::kRemainingGeometry;
  double vpl = raimProtectionLevels(g, plain).vpl_m;
  for (int i = 0; i < g.numSats(); ++i) vpl = std::max(vpl, raimProtectionLevels(g.without(i), plain).vpl_m);
  EXPECT_DOUBLE_EQ(raimFdeProtectionLevels(g, plain).vpl_m, vpl);
  // Up to four out of ten (five would leave no redundancy): Σ C(10, r), r ≤ 4 = 385 outcomes.
  RaimConfig deep;
  deep.max_exclusions = 5;
  EXPECT_TRUE(raimFdeProtectionLevels(g, deep).available);
  // Thirty satellites, four exclusions: 31,930 outcomes, more than are predicted: no PL, and why.
  std::vector<SatLook> sky;
  for (int i = 0; i < 30; ++i) sky.push_back({SatId{Constellation::kGps, i + 1}, {0.21 * i * 7.0, 0.15 + 0.045 * i}});
  const Geometry big = buildGeometry(sky, ErrorModel{}, 9.0);
  deep.max_exclusions = 4;
  const RaimPl refused = raimFdeProtectionLevels(big, deep);
  EXPECT_FALSE(refused.available);
  EXPECT_NE(refused.reason.find("31930 exclusion outcomes"), std::string::npos) << refused.reason;
  deep.max_exclusions = 2;  // 465 outcomes
  EXPECT_TRUE(raimFdeProtectionLevels(big, deep).available);
}

/// Whatever the measurements, the PL a receiver reports after FDE is one of the outcomes the
/// prediction takes the maximum over: it never exceeds the predicted PL with exclusion.
TEST(ExclusionPl, NoLiveFdePlExceedsThePredictionWithExclusion) {
  const Geometry g = addExampleGeometry();
  const ErrorModel model = ismWith(1e-5, 1e-4);
  std::mt19937 rng(2026);
  std::normal_distribution<double> noise;
  std::uniform_real_distribution<double> bias(0.0, 120.0);
  RaimConfig raim2;
  raim2.max_exclusions = 2;
  const RaimPl raim_pred = raimFdeProtectionLevels(g, RaimConfig{}), raim2_pred = raimFdeProtectionLevels(g, raim2);
  const AraimConfig acfg;
  const AraimResult araim_pred = araimFdeProtectionLevels(g, model, acfg);
  ASSERT_TRUE(raim_pred.available && raim2_pred.available && araim_pred.pl_computed);
  int raim_outcomes = 0, araim_outcomes = 0, exclusions = 0;
  for (int k = 0; k < 600; ++k) {
    Eigen::VectorXd y(g.numSats());
    for (int i = 0; i < g.numSats(); ++i) y[i] = g.sigma_int[i] * noise(rng);
    y[k % g.numSats()] += k % 3 == 0 ? 0.0 : bias(rng);
    if (k % 5 == 0) y[(k / 5) % g.numSats()] += bias(rng);  // now and then a second fault
    for (const auto& [cfg, pred] : {std::pair{RaimConfig{}, raim_pred}, std::pair{raim2, raim2_pred}}) {
      const RaimFdeResult r = raimFde(g, y, cfg);
      if (!r.pl.available) continue;
      ++raim_outcomes;
      exclusions += r.fault_excluded ? 1 : 0;
      EXPECT_LE(r.pl.hpl_m, pred.hpl_m + 1e-9) << k;
      EXPECT_LE(r.pl.vpl_m, pred.vpl_m + 1e-9) << k;
    }
    const AraimFdeResult a = araimFde(g, y, model, acfg);
    if (!a.pl.pl_computed) continue;
    ++araim_outcomes;
    EXPECT_LE(a.pl.hpl_m, araim_pred.hpl_m + 1e-9) << k;
    EXPECT_LE(a.pl.vpl_m, araim_pred.vpl_m + 1e-9) << k;
  }
  EXPECT_GT(raim_outcomes, 600);  // most epochs end with a PL, many after an exclusion
  EXPECT_GT(exclusions, 200);
  EXPECT_GT(araim_outcomes, 300);
}

}  // namespace
}  // namespace skylane::integrity
