#include "integrity/pl_summary.hpp"

#include "integrity/araim/exclusion.hpp"

namespace skylane::integrity {

PlSummary summarize(const RaimPl& pl, const Requirements& req) {
  PlSummary s;
  s.pl_computed = pl.available;
  s.reason = pl.reason;
  s.hpl_m = pl.hpl_m;
  s.vpl_m = pl.vpl_m;
  s.available = pl.available && pl.hpl_m <= req.hal_m && pl.vpl_m <= req.val_m;
  if (pl.available && !s.available) s.reason = pl.hpl_m > req.hal_m ? "HPL exceeds HAL" : "VPL exceeds VAL";
  return s;
}

PlSummary summarize(const AraimResult& r) {
  PlSummary s;
  s.pl_computed = r.pl_computed;
  s.available = r.available;
  s.reason = r.reason;
  s.hpl_m = r.hpl_m;
  s.vpl_m = r.vpl_m;
  s.emt_m = r.emt_m;
  s.sigma_acc_m = r.sigma_acc_v_m;
  s.fault_modes = r.fault_modes;
  return s;
}

PlSummary protectionLevels(const Geometry& g, IntegrityMethod method, const ErrorModel& model, const RaimConfig& raim,
                           const AraimConfig& araim, bool with_exclusion) {
  if (method == IntegrityMethod::kAraim) {
    return summarize(with_exclusion ? araimFdeProtectionLevels(g, model, araim) : araimProtectionLevels(g, model, araim));
  }
  return summarize(with_exclusion ? raimFdeProtectionLevels(g, raim) : raimProtectionLevels(g, raim), araim.requirements);
}

}  // namespace skylane::integrity
