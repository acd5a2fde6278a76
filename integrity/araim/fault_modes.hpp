#pragma once
/// \file
/// \brief Which fault modes ARAIM monitors, and their priors.
///
/// Events are independent: each satellite i faults with P_sat,i, each constellation j with
/// P_const,j (a constellation fault removes all of its satellites). N_fault,max is the smallest r
/// with P(more than r events) ≤ P_THRES (J. Blanch et al., "Baseline Advanced RAIM User Algorithm
/// and Possible Improvements", IEEE TAES 51(1), 2015, Eq. 74). Three rules form the modes:
///
///  * `kAddsUntilThreshold` (default) — the rule of the WG-C "ARAIM Airborne Algorithm Description
///    Document" v4.2 as Stanford's reference implementation, MAAST for ARAIM (J. Blanch, 2024),
///    codes it: every combination of up to max(N_fault,max, 2) events, in order of the number of
///    satellites it removes (ties: fewer events first, then the events' order — satellites, then
///    constellations); the combinations whose prior exceeds PHMI are always monitored, the others
///    are added one at a time, in that order, only while P_not_monitored > P_THRES. What is left
///    is P_not_monitored. It monitors no more than it must to reach P_THRES.
///  * `kJointEvents` — every combination of up to N_fault,max events (ADD v3.0 §2.3, TAES 2015):
///    safe, but it monitors weak subsets (one constellation out plus a satellite of the other)
///    that the reference leaves to P_not_monitored, and their PLs can cost availability.
///  * `kBlanch2012` — Blanch et al., "Advanced RAIM user algorithm description", ION GNSS 2012:
///    separate N_sat,max and N_const,max against the same threshold and no mixed satellite +
///    constellation modes. It gives 57 modes for 10 satellites in two constellations with
///    P_sat = P_const = 1e-4, P_THRES = 4e-8, but leaves the mixed modes (≈ 1e-7 there) neither
///    monitored nor counted.
///
/// Combinations that remove the same satellites are merged (priors added). Fault consolidation
/// (MAAST's `fc_thres`, off by default): a combination that removes only satellites of one
/// constellation and whose prior is below fc_thres × that constellation's fault prior is folded
/// into the constellation mode (its prior added there) before the selection.

#include "integrity/gnss/satellite_id.hpp"

#include <vector>

namespace skylane::integrity {

/// \brief How fault modes are formed.
enum class FaultModeRule {
  kAddsUntilThreshold,  ///< ADD v4.2 / MAAST for ARAIM (default)
  kJointEvents,         ///< ADD v3.0 / TAES 2015: every combination up to N_fault,max
  kBlanch2012,          ///< ION GNSS 2012: separate satellite and constellation counts, no mixing
};

/// \brief The rule's settings.
struct FaultModeOptions {
  FaultModeRule rule = FaultModeRule::kAddsUntilThreshold;
  double p_thres = 8e-8;  ///< P_THRES: the unmonitored probability allowed
  /// Total integrity budget: under `kAddsUntilThreshold` a mode whose prior exceeds it is always
  /// monitored (MAAST uses 1e-7, the LPV-200 PHMI_vert + PHMI_hor).
  double phmi = 1e-7;
  double fc_thres = 0.0;  ///< fault consolidation threshold in [0, 1); 0 = off (MAAST's LPV-200 example: 0.01)
};

/// \brief One fault mode: the satellites it removes and its prior probability.
struct FaultMode {
  std::vector<int> removed;  ///< indices into the satellite list, ascending
  double prior = 0.0;        ///< P(exactly these events): ∏ p_e · ∏_{others} (1 − p_e), summed over merges
  double event_prior = 0.0;  ///< ∏ p_e of its events (summed over merges): the ISM's nominal rate
  int events = 0;            ///< number of events (smallest over merged combinations)
};

/// \brief The monitored fault modes.
struct FaultModeSet {
  std::vector<FaultMode> modes;  ///< fewest removed satellites first
  double p_not_monitored = 0.0;  ///< P(fault combinations not monitored); unmonitorable priors are added later
  int n_fault_max = 0;
};

/// \brief P(at least r of the independent events occur): exact for r ≤ 3, the bound
/// (Σp)^r / r! above (TAES 2015 Eq. 74).
[[nodiscard]] double probabilityOfAtLeast(const std::vector<double>& p_events, int r);

/// \brief The fault modes for satellites of the given constellations.
/// \param sats constellation of each satellite (indices are the satellite indices)
/// \param p_sat prior of each satellite's fault
/// \param p_const prior of a constellation fault, per Constellation value
[[nodiscard]] FaultModeSet determineFaultModes(const std::vector<Constellation>& sats, const std::vector<double>& p_sat,
                                               const std::vector<double>& p_const, const FaultModeOptions& options);

/// \brief As above with the default PHMI and no consolidation.
[[nodiscard]] FaultModeSet determineFaultModes(const std::vector<Constellation>& sats, const std::vector<double>& p_sat,
                                               const std::vector<double>& p_const, double p_thres,
                                               FaultModeRule rule = FaultModeRule::kAddsUntilThreshold);

}  // namespace skylane::integrity
