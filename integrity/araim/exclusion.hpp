#pragma once
/// \file
/// \brief ARAIM protection levels after a fault exclusion, with the integrity budget allocated to
/// the exclusion outcomes (docs/method.md §4.3).
///
/// J. Blanch, T. Walter, P. Enge, "Protection Levels after Fault Exclusion for Advanced RAIM",
/// NAVIGATION 64(4) 505–513, 2017; the EU-US ARAIM Working Group's "ARAIM Airborne Algorithm
/// Description Document" v4.2 and its reference implementation MAAST for ARAIM (J. Blanch,
/// Stanford GPS Laboratory, 2024; `usr_vhpl_araim` with `fde_flag`). The exclusion candidates
/// are fixed before any measurement: every satellite, and — with `exclude_constellations`, MAAST's
/// `fde_wf_flag` — every constellation whose fault prior exceeds the total integrity budget
/// (MAAST's wide-fault candidates, P_const > 1e-7 for LPV-200).
/// HMI is the union of HMI under each outcome (no exclusion, exclusion of candidate k), so
///
///   P(HMI) ≤ Σ_outcomes P(HMI ∧ outcome) ≤ Σ_outcomes ρ·P_HMI = P_HMI,  ρ = 1/(N_exc + 1).
///
/// The outcome "exclude k" happens only when every test of subset k passes,
/// |x̂^(k,j) − x̂^(k)| ≤ T_k,j. Under a fault mode m of the all-in-view selection, the sub-subset
/// (k, j) = k without m's satellites is fault-free, so |x̂^(k) − x| ≤ |x̂^(k,j) − x| + T_k,j; if
/// m's satellites are all excluded, x̂^(k) itself is fault-free. The PL of outcome k therefore
/// solves Eq. (4.5) over the all-in-view modes restricted to k's satellites (merged where they
/// coincide; those inside k fall to the fault-free term) with budgets ρ·𝓑_q, and P_not_monitored
/// of the all-in-view selection. A wrong exclusion is one of these modes, not an extra term.

#include "integrity/araim/mhss.hpp"

#include <vector>

namespace skylane::integrity {

/// \brief The exclusion candidates of `g`, each the satellite indices it removes (ascending):
/// every satellite, then — with cfg.exclude_constellations and two or more constellations in
/// view — every constellation whose P_const exceeds the total budget P_HMI,V + P_HMI,H.
[[nodiscard]] std::vector<std::vector<int>> exclusionCandidates(const Geometry& g, const ErrorModel& model,
                                                                const AraimConfig& cfg);

/// \brief ρ = 1/(N_exc + 1): the share of the integrity budget of each outcome of FDE.
[[nodiscard]] double exclusionBudgetShare(std::size_t n_candidates);

/// \brief The fault modes of the subset without `excluded` (ascending indices into the
/// all-in-view satellites): each mode keeps its satellites that remain, renumbered; modes left
/// with none are dropped (the fault-free term covers them); coinciding modes are merged (priors
/// added). P_not_monitored and N_fault,max are those of the all-in-view selection.
[[nodiscard]] FaultModeSet restrictFaultModes(const FaultModeSet& all_in_view, const std::vector<int>& excluded);

/// \brief `g` without the satellites `excluded` (ascending indices).
[[nodiscard]] Geometry withoutSatellites(const Geometry& g, const std::vector<int>& excluded);

/// \brief The protection levels of the outcome "exclude `excluded`" (ascending indices into
/// `g`): Eq. (4.5) over the restricted all-in-view modes on the remaining geometry, with the
/// budget share `budget_share` (ρ). Its subsets carry the thresholds T_k,j of the exclusion test.
[[nodiscard]] AraimResult araimLevelsAfterExclusion(const Geometry& g, const FaultModeSet& all_in_view_modes,
                                                    const std::vector<int>& excluded, const AraimConfig& cfg,
                                                    double budget_share);

/// \brief The predicted protection levels of a user who excludes (availability with FDE, as
/// MAAST's `fde_flag`): the maximum over the no-exclusion outcome and every candidate's outcome,
/// each with ρ·P_HMI; the EMT and σ_acc are the maxima too. Not computable when any outcome's
/// PL is not (MAAST: infinite).
[[nodiscard]] AraimResult araimFdeProtectionLevels(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg);

}  // namespace skylane::integrity
