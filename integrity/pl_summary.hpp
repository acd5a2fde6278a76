#pragma once
/// \file
/// \brief A method-neutral view of one epoch's protection levels (RAIM or ARAIM).

#include "integrity/araim/mhss.hpp"
#include "integrity/raim/raim.hpp"
#include "integrity/requirements.hpp"

#include <string>

namespace skylane::integrity {

/// \brief Which integrity algorithm forms the protection levels.
enum class IntegrityMethod { kRaim, kAraim };

/// \brief Method-neutral outcome of one epoch.
struct PlSummary {
  bool pl_computed = false;
  bool available = false;
  std::string reason;
  double hpl_m = 0, vpl_m = 0;
  double emt_m = 0, sigma_acc_m = 0;  ///< ARAIM only
  int fault_modes = 0;                ///< ARAIM only
};

/// \brief Summary of a RAIM result against HAL/VAL.
[[nodiscard]] PlSummary summarize(const RaimPl& pl, const Requirements& req);
/// \brief Summary of an ARAIM result.
[[nodiscard]] PlSummary summarize(const AraimResult& r);

/// \brief Protection levels of a geometry with the chosen method (availability from the ARAIM
/// config's requirements for both methods). `with_exclusion`: the predicted PLs of a user who
/// detects and excludes (araimFdeProtectionLevels, raimFdeProtectionLevels), the maximum over
/// the exclusion outcomes each with its share of the budget; otherwise those of detection only.
[[nodiscard]] PlSummary protectionLevels(const Geometry& g, IntegrityMethod method, const ErrorModel& model,
                                         const RaimConfig& raim, const AraimConfig& araim, bool with_exclusion = false);

}  // namespace skylane::integrity
