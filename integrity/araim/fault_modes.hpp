#pragma once
/// \file
/// \brief Which fault modes ARAIM monitors, and their priors.
///
/// Events are independent: each satellite i faults with P_sat,i, each constellation j with
/// P_const,j (a constellation fault removes all of its satellites). Following J. Blanch et al.,
/// "Baseline Advanced RAIM User Algorithm and Possible Improvements", IEEE TAES 51(1), 2015, and
/// the WG-C ARAIM ADD v3.0 (2017) §2.3:
///  * N_fault,max is the smallest r with P(more than r events) ≤ P_THRES;
///  * every combination of up to N_fault,max events is a fault mode; combinations that remove
///    the same satellites are merged (priors added);
///  * P_not_monitored = P(more than N_fault,max events) + priors of unmonitorable modes.
/// `kBlanch2012` is the earlier rule of Blanch et al., "Advanced RAIM user algorithm
/// description", ION GNSS 2012: separate N_sat,max and N_const,max against the same threshold
/// and no mixed satellite + constellation modes. It gives 57 modes for 10 satellites in two
/// constellations with P_sat = P_const = 1e-4, P_THRES = 4e-8, but leaves the mixed modes
/// (≈ 1e-7 there) neither monitored nor counted — so it is not skylane's default.

#include "integrity/gnss/satellite_id.hpp"

#include <vector>

namespace skylane::integrity {

/// \brief How fault modes are formed.
enum class FaultModeRule {
  kJointEvents,  ///< ADD v3.0 / TAES 2015 (default)
  kBlanch2012,   ///< ION GNSS 2012: separate satellite and constellation counts, no mixing
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
  std::vector<FaultMode> modes;
  double p_not_monitored = 0.0;  ///< P(more events than monitored); unmonitorable priors are added later
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
                                               const std::vector<double>& p_const, double p_thres,
                                               FaultModeRule rule = FaultModeRule::kJointEvents);

}  // namespace skylane::integrity
