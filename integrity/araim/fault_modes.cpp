#include "integrity/araim/fault_modes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace skylane::integrity {
namespace {

/// More simultaneous events than this are never enumerated: with any realistic ISM the
/// probability of four independent faults is far below every P_THRES (1e-20 for P = 1e-5).
constexpr int kMaxEnumeratedEvents = 3;
/// MAAST enumerates at least the pairs of events, even when N_fault,max is 1, so that the
/// selection can add the strongest of them when the singles alone leave too much unmonitored.
constexpr int kMinEnumeratedEvents = 2;
/// Satellites + constellations an event list can hold (far above any sky: 4 constellations' full view).
constexpr int kMaxEvents = 256;

struct Event {
  int satellite = -1;        ///< a satellite fault: its index (no list to allocate)
  std::vector<int> removes;  ///< a constellation fault: its satellites' indices, ascending
  double p = 0.0;
};

/// One combination of events, before merging by removed set.
struct Combination {
  std::array<int, kMaxEnumeratedEvents> events{};  ///< event indices, ascending (the first n_events)
  int n_events = 0;
  std::vector<int> removed;  ///< union of the events' satellites, ascending
  double prior = 0.0;        ///< ∏_{e∈E} p_e ∏_{e∉E} (1 − p_e)
  double event_prior = 0.0;  ///< ∏_{e∈E} p_e
};

std::vector<double> probabilities(const std::vector<Event>& events) {
  std::vector<double> p;
  p.reserve(events.size());
  for (const Event& e : events) p.push_back(e.p);
  return p;
}

int nFaultMax(const std::vector<double>& p, double p_thres) {
  int r = 0;
  while (r < kMaxEnumeratedEvents && probabilityOfAtLeast(p, r + 1) > p_thres) ++r;
  return r;
}

/// ln ∏(1 − p_e): P(no event) is its exponential, P(at least one event) −expm1 of it (without the
/// cancellation of 1 − a number near 1).
double logNoFault(const std::vector<Event>& events) {
  double log_nf = 0.0;
  for (const Event& e : events) log_nf += std::log1p(-e.p);
  return log_nf;
}

double noFault(const std::vector<Event>& events) { return std::exp(logNoFault(events)); }

/// Calls visit(indices, prior, event_prior) for every combination of exactly k events with
/// nonzero probability, in lexicographic order of the event indices (MAAST's order); the
/// indices are into `events`. No allocation per combination.
template <class Visit>
void forEachCombination(const std::vector<Event>& events, int k, double p_nf, Visit&& visit) {
  int usable[kMaxEvents];
  int n = 0;
  for (int e = 0; e < static_cast<int>(events.size()) && n < kMaxEvents; ++e) {
    if (events[static_cast<std::size_t>(e)].p > 0.0) usable[n++] = e;
  }
  if (k > n || k > kMaxEnumeratedEvents) return;
  int idx[kMaxEnumeratedEvents], pick[kMaxEnumeratedEvents];
  for (int i = 0; i < k; ++i) idx[i] = i;
  while (true) {
    double prior = p_nf, event_prior = 1.0;
    for (int i = 0; i < k; ++i) {
      pick[i] = usable[idx[i]];
      const double p = events[static_cast<std::size_t>(pick[i])].p;
      prior *= p / (1.0 - p);
      event_prior *= p;
    }
    visit(pick, k, prior, event_prior);
    int i = k - 1;  // next combination: bump the last index that can move
    while (i >= 0 && idx[i] == n - k + i) --i;
    if (i < 0) return;
    ++idx[i];
    for (int j = i + 1; j < k; ++j) idx[j] = idx[j - 1] + 1;
  }
}

Combination makeCombination(const std::vector<Event>& events, const int* pick, int k, double prior, double event_prior) {
  Combination c;
  c.prior = prior;
  c.event_prior = event_prior;
  std::size_t count = 0;
  for (int i = 0; i < k; ++i) {
    const Event& e = events[static_cast<std::size_t>(pick[i])];
    count += e.satellite >= 0 ? 1 : e.removes.size();
  }
  c.removed.reserve(count);
  for (int i = 0; i < k; ++i) {
    const Event& e = events[static_cast<std::size_t>(pick[i])];
    c.events[static_cast<std::size_t>(c.n_events++)] = pick[i];
    if (e.satellite >= 0) {
      c.removed.push_back(e.satellite);
    } else {
      c.removed.insert(c.removed.end(), e.removes.begin(), e.removes.end());
    }
  }
  if (k > 1) {  // one event's satellites are already ascending and distinct
    std::sort(c.removed.begin(), c.removed.end());
    c.removed.erase(std::unique(c.removed.begin(), c.removed.end()), c.removed.end());
  }
  return c;
}

/// Every combination of exactly k events with nonzero probability, in MAAST's order, appended to `out`.
void combinationsOfSize(const std::vector<Event>& events, int k, double p_nf, std::vector<Combination>& out) {
  forEachCombination(events, k, p_nf, [&](const int* pick, int kk, double prior, double event_prior) {
    out.push_back(makeCombination(events, pick, kk, prior, event_prior));
  });
}

std::vector<Combination> combinationsUpTo(const std::vector<Event>& events, int max_events, double p_nf) {
  std::vector<Combination> out;
  for (int k = 1; k <= max_events; ++k) combinationsOfSize(events, k, p_nf, out);
  return out;
}

/// MAAST's fault consolidation: within each constellation, the combinations removing only its
/// satellites with a prior below fc_thres × the constellation fault's are folded into the
/// constellation mode.
void consolidateIntoConstellations(std::vector<Combination>& combos, int first_const_event, double fc_thres) {
  if (!(fc_thres > 0.0)) return;
  for (std::size_t c = 0; c < combos.size(); ++c) {
    if (combos[c].n_events != 1 || combos[c].events[0] < first_const_event) continue;
    const std::vector<int> own = combos[c].removed;
    const double limit = fc_thres * combos[c].prior;
    double prior_in = 0.0, event_prior_in = 0.0;
    std::vector<Combination> kept;
    kept.reserve(combos.size());
    std::size_t c_kept = 0;  // the constellation mode's position after the removals
    for (std::size_t k = 0; k < combos.size(); ++k) {
      const Combination& m = combos[k];
      const bool inside = std::includes(own.begin(), own.end(), m.removed.begin(), m.removed.end());
      if (k != c && inside && m.prior < limit) {
        prior_in += m.prior;
        event_prior_in += m.event_prior;
        continue;
      }
      if (k == c) c_kept = kept.size();
      kept.push_back(m);
    }
    kept[c_kept].prior += prior_in;
    kept[c_kept].event_prior += event_prior_in;
    combos = std::move(kept);
    c = c_kept;
  }
}

/// The reference selection: fewest removed satellites first; priors above PHMI always kept,
/// the others added while P_not_monitored > P_THRES. Returns P_not_monitored.
double selectUntilThreshold(std::vector<Combination>& combos, double p_any, const FaultModeOptions& o) {
  std::stable_sort(combos.begin(), combos.end(),
                   [](const Combination& a, const Combination& b) { return a.removed.size() < b.removed.size(); });
  double p_nm = p_any;
  for (const Combination& c : combos) {
    if (c.prior > o.phmi) p_nm -= c.prior;
  }
  std::vector<Combination> kept;
  for (Combination& c : combos) {
    if (c.prior > o.phmi) {
      kept.push_back(std::move(c));
    } else if (p_nm > o.p_thres) {
      p_nm -= c.prior;
      kept.push_back(std::move(c));
    }
  }
  combos = std::move(kept);
  return std::max(0.0, p_nm);
}

/// An upper bound on the prior of any combination of k events: p_nf times the k largest
/// p_e/(1 − p_e), inflated by 1e-12 over the products' round-off.
double largestPriorOf(const std::vector<Event>& events, int k, double p_nf) {
  std::array<double, kMaxEnumeratedEvents> top{};  // descending
  for (const Event& e : events) {
    double u = e.p / (1.0 - e.p);
    for (int i = 0; i < k; ++i) {
      if (u > top[static_cast<std::size_t>(i)]) std::swap(u, top[static_cast<std::size_t>(i)]);
    }
  }
  double bound = p_nf * (1.0 + 1e-12);
  for (int i = 0; i < k; ++i) bound *= top[static_cast<std::size_t>(i)];
  return bound;
}

/// The reference selection when the monitored-always combinations (prior > PHMI) alone leave
/// P_nm ≤ P_THRES — the usual case with LPV-200 ISMs: then the loop adds nothing, and only those
/// combinations are built. Returns false (and leaves `combos` empty) when more are needed.
bool selectLargeOnly(const std::vector<Event>& events, int depth, double p_nf, double p_any, const FaultModeOptions& o,
                     std::vector<Combination>& combos, double& p_nm) {
  double p = p_any;
  combos.reserve(events.size());
  for (int k = 1; k <= depth; ++k) {
    // No combination of k events can exceed PHMI: none to visit.
    if (largestPriorOf(events, k, p_nf) <= o.phmi) continue;
    forEachCombination(events, k, p_nf, [&](const int* pick, int kk, double prior, double event_prior) {
      if (prior <= o.phmi) return;
      p -= prior;
      combos.push_back(makeCombination(events, pick, kk, prior, event_prior));
    });
  }
  if (p > o.p_thres) {
    combos.clear();
    return false;
  }
  p_nm = std::max(0.0, p);
  return true;
}

/// Merges combinations by removed set; fewest removed satellites first, then lexicographic.
std::vector<FaultMode> mergeByRemovedSet(std::vector<Combination>& combos) {
  const auto before = [](const Combination& a, const Combination& b) {
    return a.removed.size() != b.removed.size() ? a.removed.size() < b.removed.size() : a.removed < b.removed;
  };
  // The usual single events arrive in order already: a stable sort would leave them as they are.
  if (!std::is_sorted(combos.begin(), combos.end(), before)) std::stable_sort(combos.begin(), combos.end(), before);
  std::vector<FaultMode> out;
  out.reserve(combos.size());
  for (Combination& c : combos) {
    const int events = c.n_events;
    if (out.empty() || out.back().removed != c.removed) {
      FaultMode m;
      m.removed = std::move(c.removed);
      m.events = events;
      out.push_back(std::move(m));
    }
    FaultMode& m = out.back();
    m.prior += c.prior;
    m.event_prior += c.event_prior;
    m.events = std::min(m.events, events);
  }
  return out;
}

struct Events {
  std::vector<Event> all;  ///< satellites first (in satellite order), then constellations
  int first_const = 0;
};

Events buildEvents(const std::vector<Constellation>& sats, const std::vector<double>& p_sat,
                   const std::vector<double>& p_const) {
  if (sats.size() != p_sat.size()) throw std::invalid_argument("determineFaultModes: one P_sat per satellite");
  if (p_const.size() < static_cast<std::size_t>(kNumConstellations)) {
    throw std::invalid_argument("determineFaultModes: one P_const per constellation");
  }
  Events ev;
  ev.all.reserve(sats.size() + static_cast<std::size_t>(kNumConstellations));
  for (std::size_t i = 0; i < sats.size(); ++i) ev.all.push_back({static_cast<int>(i), {}, p_sat[i]});
  ev.first_const = static_cast<int>(ev.all.size());
  for (Constellation c : kAllConstellations) {
    Event e;
    e.removes.reserve(sats.size());
    for (std::size_t i = 0; i < sats.size(); ++i) {
      if (sats[i] == c) e.removes.push_back(static_cast<int>(i));
    }
    if (e.removes.empty()) continue;
    e.p = p_const[static_cast<std::size_t>(c)];
    ev.all.push_back(std::move(e));
  }
  for (const Event& e : ev.all) {
    if (!(e.p >= 0.0 && e.p < 1.0)) throw std::invalid_argument("determineFaultModes: a prior outside [0, 1)");
  }
  if (ev.all.size() > static_cast<std::size_t>(kMaxEvents)) {
    throw std::invalid_argument("determineFaultModes: " + std::to_string(ev.all.size()) + " fault events, at most " +
                                std::to_string(kMaxEvents));
  }
  return ev;
}

/// ION GNSS 2012: satellite and constellation combinations counted and enumerated apart.
FaultModeSet blanch2012Modes(const Events& ev, const FaultModeOptions& o) {
  const std::vector<Event> sat_events(ev.all.begin(), ev.all.begin() + ev.first_const);
  const std::vector<Event> const_events(ev.all.begin() + ev.first_const, ev.all.end());
  const std::vector<double> ps = probabilities(sat_events), pc = probabilities(const_events);
  const int n_sat = nFaultMax(ps, o.p_thres), n_const = nFaultMax(pc, o.p_thres);
  FaultModeSet out;
  out.n_fault_max = std::max(n_sat, n_const);
  out.p_not_monitored = probabilityOfAtLeast(ps, n_sat + 1) + probabilityOfAtLeast(pc, n_const + 1);
  std::vector<Combination> combos = combinationsUpTo(sat_events, n_sat, noFault(sat_events));
  std::vector<Combination> cc = combinationsUpTo(const_events, n_const, noFault(const_events));
  for (Combination& c : cc) {
    for (int k = 0; k < c.n_events; ++k) c.events[static_cast<std::size_t>(k)] += ev.first_const;
    combos.push_back(std::move(c));
  }
  consolidateIntoConstellations(combos, ev.first_const, o.fc_thres);
  out.modes = mergeByRemovedSet(combos);
  return out;
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
                                 const std::vector<double>& p_const, const FaultModeOptions& o) {
  if (!(o.p_thres > 0.0 && o.p_thres < 1.0) || !(o.phmi > 0.0 && o.phmi < 1.0)) {
    throw std::invalid_argument("determineFaultModes: P_THRES and PHMI must be in (0, 1)");
  }
  if (!(o.fc_thres >= 0.0 && o.fc_thres < 1.0)) {
    throw std::invalid_argument("determineFaultModes: fc_thres must be in [0, 1), got " + std::to_string(o.fc_thres));
  }
  const Events ev = buildEvents(sats, p_sat, p_const);
  if (o.rule == FaultModeRule::kBlanch2012) return blanch2012Modes(ev, o);
  const std::vector<double> p = probabilities(ev.all);
  FaultModeSet out;
  out.n_fault_max = nFaultMax(p, o.p_thres);
  const bool adds = o.rule == FaultModeRule::kAddsUntilThreshold;
  const int depth = adds ? std::min(kMaxEnumeratedEvents, std::max(out.n_fault_max, kMinEnumeratedEvents))
                         : out.n_fault_max;
  std::vector<Combination> combos;
  // Consolidation can lift a constellation mode above PHMI, so the shortcut needs it off.
  const double log_nf = logNoFault(ev.all), p_nf = std::exp(log_nf), p_any = -std::expm1(log_nf);
  if (adds && !(o.fc_thres > 0.0) && selectLargeOnly(ev.all, depth, p_nf, p_any, o, combos, out.p_not_monitored)) {
    out.modes = mergeByRemovedSet(combos);
    return out;
  }
  combos = combinationsUpTo(ev.all, depth, p_nf);
  consolidateIntoConstellations(combos, ev.first_const, o.fc_thres);
  out.p_not_monitored = adds ? selectUntilThreshold(combos, p_any, o)
                             : probabilityOfAtLeast(p, out.n_fault_max + 1);
  out.modes = mergeByRemovedSet(combos);
  return out;
}

FaultModeSet determineFaultModes(const std::vector<Constellation>& sats, const std::vector<double>& p_sat,
                                 const std::vector<double>& p_const, double p_thres, FaultModeRule rule) {
  FaultModeOptions o;
  o.rule = rule;
  o.p_thres = p_thres;
  return determineFaultModes(sats, p_sat, p_const, o);
}

}  // namespace skylane::integrity
