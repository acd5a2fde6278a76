#include "integrity/araim/exclusion.hpp"

#include <algorithm>
#include <map>

namespace skylane::integrity {

std::vector<std::vector<int>> exclusionCandidates(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg) {
  std::vector<std::vector<int>> out;
  const int n = g.numSats();
  for (int i = 0; i < n; ++i) out.push_back({i});
  if (!cfg.exclude_constellations || g.clocks.size() < 2) return out;  // the only constellation: nothing left
  const double phmi = cfg.requirements.phmi_vert + cfg.requirements.phmi_hor;
  for (Constellation c : g.clocks) {
    if (!(model.of(c).pconst > phmi)) continue;
    std::vector<int> members;
    for (int i = 0; i < n; ++i) {
      if (g.sats[static_cast<std::size_t>(i)].constellation == c) members.push_back(i);
    }
    if (members.size() > 1) out.push_back(std::move(members));  // one satellite: already a candidate
  }
  return out;
}

double exclusionBudgetShare(std::size_t n_candidates) { return 1.0 / (static_cast<double>(n_candidates) + 1.0); }

FaultModeSet restrictFaultModes(const FaultModeSet& all_in_view, const std::vector<int>& excluded) {
  FaultModeSet out;
  out.p_not_monitored = all_in_view.p_not_monitored;
  out.n_fault_max = all_in_view.n_fault_max;
  std::map<std::vector<int>, std::size_t> seen;  // restricted satellites → index in out.modes
  for (const FaultMode& m : all_in_view.modes) {
    FaultMode r;
    for (int i : m.removed) {
      if (std::binary_search(excluded.begin(), excluded.end(), i)) continue;
      // Renumber: the index among the remaining satellites.
      const auto below = std::lower_bound(excluded.begin(), excluded.end(), i) - excluded.begin();
      r.removed.push_back(i - static_cast<int>(below));
    }
    if (r.removed.empty()) continue;  // its satellites are all excluded: x̂^(k) is fault-free under it
    const auto [it, fresh] = seen.emplace(r.removed, out.modes.size());
    if (!fresh) {
      FaultMode& kept = out.modes[it->second];
      kept.prior += m.prior;
      kept.event_prior += m.event_prior;
      kept.events = std::min(kept.events, m.events);
      continue;
    }
    r.prior = m.prior;
    r.event_prior = m.event_prior;
    r.events = m.events;
    out.modes.push_back(std::move(r));
  }
  std::stable_sort(out.modes.begin(), out.modes.end(),
                   [](const FaultMode& a, const FaultMode& b) { return a.removed.size() < b.removed.size(); });
  return out;
}

Geometry withoutSatellites(const Geometry& g, const std::vector<int>& excluded) {
  Geometry out = g;
  for (auto it = excluded.rbegin(); it != excluded.rend(); ++it) out = out.without(*it);  // highest index first
  return out;
}

AraimResult araimLevelsAfterExclusion(const Geometry& g, const FaultModeSet& all_in_view_modes,
                                      const std::vector<int>& excluded, const AraimConfig& cfg, double budget_share) {
  const Geometry gk = withoutSatellites(g, excluded);
  AraimResult r = araimLevelsOverModes(gk, restrictFaultModes(all_in_view_modes, excluded), cfg, budget_share);
  return r;
}

namespace {

/// Folds outcome `r` into the running maxima `out` (PLs, EMT, σ_acc; availability is the AND).
void foldOutcome(AraimResult& out, const AraimResult& r) {
  if (!out.pl_computed) return;  // an earlier outcome has no PL: its reason stands
  if (!r.pl_computed) {
    out.pl_computed = out.available = false;
    out.reason = "an exclusion outcome has no protection level: " + r.reason;
    return;
  }
  out.hpl_m = std::max(out.hpl_m, r.hpl_m);
  out.vpl_m = std::max(out.vpl_m, r.vpl_m);
  out.hpl_axis_m = {std::max(out.hpl_axis_m[0], r.hpl_axis_m[0]), std::max(out.hpl_axis_m[1], r.hpl_axis_m[1])};
  out.hpl_equal_allocation_m = std::max(out.hpl_equal_allocation_m, r.hpl_equal_allocation_m);
  out.vpl_equal_allocation_m = std::max(out.vpl_equal_allocation_m, r.vpl_equal_allocation_m);
  out.emt_m = std::max(out.emt_m, r.emt_m);
  out.sigma_acc_v_m = std::max(out.sigma_acc_v_m, r.sigma_acc_v_m);
  if (out.available && !r.available) {
    out.available = false;
    out.reason = "after an exclusion: " + r.reason;
  }
}

}  // namespace

AraimResult araimFdeProtectionLevels(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg) {
  AraimResult out = araimProtectionLevels(g, model, cfg);
  if (!out.accuracy_computed) return out;  // the geometry itself is short: the reason says why
  const FaultModeSet modes = araimFaultModes(g, model, cfg);
  const std::vector<std::vector<int>> candidates = exclusionCandidates(g, model, cfg);
  const double rho = exclusionBudgetShare(candidates.size());
  out = araimLevelsOverModes(g, modes, cfg, rho);
  if (!out.pl_computed) return out;
  for (const std::vector<int>& k : candidates) foldOutcome(out, araimLevelsAfterExclusion(g, modes, k, cfg, rho));
  return out;
}

}  // namespace skylane::integrity
