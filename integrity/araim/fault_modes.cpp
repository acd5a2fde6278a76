#include "integrity/araim/fault_modes.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <stdexcept>

namespace skylane::integrity {
namespace {

/// More simultaneous events than this are never enumerated: with any realistic ISM the
/// probability of four independent faults is far below every P_THRES (1e-20 for P = 1e-5).
constexpr int kMaxEnumeratedEvents = 3;

struct Event {
  std::vector<int> removes;
  double p = 0.0;
};

int nFaultMax(const std::vector<double>& p, double p_thres) {
  int r = 0;
  while (r < kMaxEnumeratedEvents && probabilityOfAtLeast(p, r + 1) > p_thres) ++r;
  return r;
}

/// Adds every combination of 1 … r events from `events` to `out` (merged by removed set).
void enumerate(const std::vector<Event>& events, int r, double p_nf, std::map<std::vector<int>, FaultMode>& out) {
  const int n = static_cast<int>(events.size());
  std::vector<int> pick;
  // Iterative combination walk: pick holds increasing event indices.
  std::function<void(int, double, double)> rec = [&](int start, double u_prod, double p_prod) {
    if (!pick.empty()) {
      std::vector<int> removed;
      for (int e : pick) removed.insert(removed.end(), events[e].removes.begin(), events[e].removes.end());
      std::sort(removed.begin(), removed.end());
      removed.erase(std::unique(removed.begin(), removed.end()), removed.end());
      FaultMode& m = out[removed];
      if (m.removed.empty()) {
        m.removed = removed;
        m.events = static_cast<int>(pick.size());
      }
      m.prior += p_nf * u_prod;  // ∏_{e∈E} p_e ∏_{e∉E} (1 − p_e)
      m.event_prior += p_prod;
      m.events = std::min(m.events, static_cast<int>(pick.size()));
    }
    if (static_cast<int>(pick.size()) == r) return;
    for (int e = start; e < n; ++e) {
      if (!(events[e].p > 0.0)) continue;
      pick.push_back(e);
      rec(e + 1, u_prod * events[e].p / (1.0 - events[e].p), p_prod * events[e].p);
      pick.pop_back();
    }
  };
  rec(0, 1.0, 1.0);
}

double noFault(const std::vector<Event>& events) {
  double p = 1.0;
  for (const Event& e : events) p *= 1.0 - e.p;
  return p;
}

}  // namespace

double probabilityOfAtLeast(const std::vector<double>& p, int r) {
  if (r <= 0) return 1.0;
  double p_nf = 1.0, s1 = 0.0, s2 = 0.0, sum = 0.0;
  for (double pe : p) {
    if (!(pe >= 0.0 && pe < 1.0)) throw std::invalid_argument("event probability outside [0, 1)");
    p_nf *= 1.0 - pe;
    const double u = pe / (1.0 - pe);
    s1 += u;
    s2 += u * u;
    sum += pe;
  }
  if (r == 1) return 1.0 - p_nf;
  if (r == 2) return std::max(0.0, 1.0 - p_nf * (1.0 + s1));
  if (r == 3) return std::max(0.0, 1.0 - p_nf * (1.0 + s1 + 0.5 * (s1 * s1 - s2)));
  double bound = 1.0;
  for (int k = 1; k <= r; ++k) bound *= sum / k;  // (Σp)^r / r!
  return std::min(1.0, bound);
}

FaultModeSet determineFaultModes(const std::vector<Constellation>& sats, const std::vector<double>& p_sat,
                                 const std::vector<double>& p_const, double p_thres, FaultModeRule rule) {
  if (sats.size() != p_sat.size()) throw std::invalid_argument("determineFaultModes: one P_sat per satellite");
  std::vector<Event> sat_events, const_events;
  for (std::size_t i = 0; i < sats.size(); ++i) sat_events.push_back({{static_cast<int>(i)}, p_sat[i]});
  for (Constellation c : kAllConstellations) {
    Event e;
    for (std::size_t i = 0; i < sats.size(); ++i) {
      if (sats[i] == c) e.removes.push_back(static_cast<int>(i));
    }
    if (e.removes.empty()) continue;
    e.p = p_const.at(static_cast<std::size_t>(c));
    const_events.push_back(e);
  }
  auto probs = [](const std::vector<Event>& ev) {
    std::vector<double> p;
    for (const Event& e : ev) p.push_back(e.p);
    return p;
  };
  FaultModeSet out;
  std::map<std::vector<int>, FaultMode> modes;
  if (rule == FaultModeRule::kJointEvents) {
    std::vector<Event> all = sat_events;
    all.insert(all.end(), const_events.begin(), const_events.end());
    const std::vector<double> p = probs(all);
    out.n_fault_max = nFaultMax(p, p_thres);
    out.p_not_monitored = probabilityOfAtLeast(p, out.n_fault_max + 1);
    enumerate(all, out.n_fault_max, noFault(all), modes);
  } else {
    const std::vector<double> ps = probs(sat_events), pc = probs(const_events);
    const int n_sat = nFaultMax(ps, p_thres), n_const = nFaultMax(pc, p_thres);
    out.n_fault_max = std::max(n_sat, n_const);
    out.p_not_monitored = probabilityOfAtLeast(ps, n_sat + 1) + probabilityOfAtLeast(pc, n_const + 1);
    enumerate(sat_events, n_sat, noFault(sat_events), modes);
    std::map<std::vector<int>, FaultMode> cmodes;
    enumerate(const_events, n_const, noFault(const_events), cmodes);
    for (auto& [k, m] : cmodes) {
      FaultMode& dst = modes[k];
      if (dst.removed.empty()) {
        dst = m;
      } else {
        dst.prior += m.prior;
        dst.event_prior += m.event_prior;
      }
    }
  }
  for (auto& [k, m] : modes) out.modes.push_back(m);
  // Fewest removed satellites first (singles, then pairs, then constellations …).
  std::stable_sort(out.modes.begin(), out.modes.end(),
                   [](const FaultMode& a, const FaultMode& b) { return a.removed.size() < b.removed.size(); });
  return out;
}

}  // namespace skylane::integrity
