#include "integrity/araim/mhss.hpp"

#include "integrity/stats.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

namespace skylane::integrity {
namespace {

/// Smallest/largest LDLᵀ pivot ratio below which a subset's normal matrix is singular (mode
/// unmonitorable): far above round-off (1e-16) so the subset covariance is still meaningful.
constexpr double kMinPivotRatio = 1e-12;
/// 3 position states + at most one clock per constellation.
constexpr int kMaxStates = 3 + kNumConstellations;
using StateMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStates, kMaxStates>;

/// Q̃(x): the normal tail, 1 for negative arguments (conservative when PL < T + b).
double modifiedTail(double x) { return x < 0.0 ? 1.0 : normalTail(x); }

/// Largest leverage h_i = w_i g_iᵀ N⁻¹ g_i, as 1 − h_i, for which a single-satellite subset is
/// taken from the rank-one down-date: N_k = N − w g gᵀ ⪰ (1 − h_i) N, so below this the
/// down-dated solution would lose more than three digits to the all-in-view one's and the
/// subset is solved from its own normal matrix instead (which also decides unmonitorable).
constexpr double kMinDowndateRedundancy = 1e-3;

struct AllInView {
  Eigen::MatrixXd A;  ///< Gᵀ W (m × n)
  StateMatrix N;      ///< Gᵀ W G, lower triangle only (all the LDLᵀ reads); the upper is zero
  /// For the rank-one down-dates (AraimConfig::subset_downdate): P = N⁻¹ and S = P Gᵀ W with
  /// every state's row (m × n); empty when not used.
  StateMatrix P;
  Eigen::MatrixXd S;
  /// The hat matrix transposed, Ht(j, i) = H_ij = g_iᵀ S_·j (n × n): row i of H is column i.
  Eigen::MatrixXd Ht;
};

/// Columns 0..cols−1 of N⁻¹ for the symmetric positive definite mk × mk matrix N (only its
/// lower triangle is read; overwritten by its unit lower-triangular factor), by an unpivoted
/// LDLᵀ factorisation and substitution — a fixed-capacity loop for these ≤ 7 × 7 systems, no
/// allocation. False when a pivot is not
/// above kMinPivotRatio × the largest (the subset's states are not fixed: unmonitorable).
bool ldltInverseColumns(StateMatrix& N, int mk, int cols, double (&X)[kMaxStates][kMaxStates]) {
  double d[kMaxStates];
  double d_max = 0.0;
  for (int j = 0; j < mk; ++j) {
    double dj = N(j, j);
    for (int k = 0; k < j; ++k) dj -= N(j, k) * N(j, k) * d[k];
    if (!(dj > 0.0)) return false;
    d[j] = dj;
    d_max = std::max(d_max, dj);
    for (int i = j + 1; i < mk; ++i) {
      double lij = N(i, j);
      for (int k = 0; k < j; ++k) lij -= N(i, k) * N(j, k) * d[k];
      N(i, j) = lij / dj;
    }
  }
  for (int j = 0; j < mk; ++j) {
    if (!(d[j] > kMinPivotRatio * d_max)) return false;
  }
  for (int q = 0; q < cols; ++q) {
    double y[kMaxStates];
    for (int i = 0; i < mk; ++i) {  // L y = e_q
      double v = i == q ? 1.0 : 0.0;
      for (int k = 0; k < i; ++k) v -= N(i, k) * y[k];
      y[i] = v;
    }
    for (int i = mk - 1; i >= 0; --i) {  // D Lᵀ x = y
      double v = y[i] / d[i];
      for (int k = i + 1; k < mk; ++k) v -= N(k, i) * X[k][q];
      X[i][q] = v;
    }
  }
  return true;
}

/// Subset solution from the all-in-view normal matrix down-dated by the removed satellites
/// (N_k = N − Σ_{i∈B} w_i g_i g_iᵀ; TAES §III-B), with the clocks of emptied constellations
/// dropped. Returns false when the mode cannot be monitored.
bool subsetSolution(const Geometry& g, const AllInView& aiv, const std::vector<int>& removed, SubsetSolution& out) {
  const int n = g.numSats(), m = g.numStates();
  if (m > kMaxStates) return false;
  // `removed` is ascending: one walk over the satellites tells kept from removed, no allocation.
  const auto isRemoved = [&removed](int i) { return std::binary_search(removed.begin(), removed.end(), i); };
  std::array<int, kMaxStates> cols{0, 1, 2};
  int mk = 3;
  for (int c = 3; c < m; ++c) {
    for (int i = 0; i < n; ++i) {
      if (g.G(i, c) != 0.0 && !isRemoved(i)) {
        cols[static_cast<std::size_t>(mk++)] = c;
        break;
      }
    }
  }
  const int kept = n - static_cast<int>(removed.size());
  if (kept < mk) return false;  // the subset cannot fix position and its clocks (Stanford: N ≥ unknowns)
  StateMatrix Nk = aiv.N;
  for (int i : removed) {
    const double w = 1.0 / (g.sigma_int[i] * g.sigma_int[i]);
    for (int a = 0; a < m; ++a) {  // rank-one down-date N_k = N − w g gᵀ
      for (int b = 0; b <= a; ++b) Nk(a, b) -= w * g.G(i, a) * g.G(i, b);
    }
  }
  StateMatrix Nr(mk, mk);
  for (int a = 0; a < mk; ++a) {
    for (int b = 0; b < mk; ++b) Nr(a, b) = Nk(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(b)]);
  }
  double X[kMaxStates][kMaxStates];  // columns q of N_k⁻¹
  if (!ldltInverseColumns(Nr, mk, 3, X)) return false;
  out.S = Eigen::MatrixXd::Zero(3, n);
  for (int i = 0, r = 0; i < n; ++i) {
    if (r < static_cast<int>(removed.size()) && removed[static_cast<std::size_t>(r)] == i) {
      ++r;
      continue;
    }
    for (int q = 0; q < 3; ++q) {
      double s = 0.0;
      for (int a = 0; a < mk; ++a) s += X[a][q] * aiv.A(cols[static_cast<std::size_t>(a)], i);
      out.S(q, i) = s;
    }
  }
  for (int q = 0; q < 3; ++q) out.sigma[q] = std::sqrt(X[q][q]);
  return std::isfinite(out.sigma[0]) && std::isfinite(out.sigma[2]);
}

/// The all-in-view covariance P = N⁻¹ and the projection S = P Gᵀ W with every state's row,
/// for the rank-one down-dates. False (down-dates unused) when N is singular.
bool setAllInViewCovariance(AllInView& aiv, const Geometry& g) {
  const int m = g.numStates(), n = g.numSats();
  StateMatrix L = aiv.N;
  double X[kMaxStates][kMaxStates];
  if (!ldltInverseColumns(L, m, m, X)) return false;
  aiv.P.resize(m, m);
  for (int a = 0; a < m; ++a) {
    for (int b = 0; b < m; ++b) aiv.P(a, b) = X[a][b];
  }
  aiv.S.resize(m, n);
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < m; ++a) {
      double v = 0.0;
      for (int b = 0; b < m; ++b) v += aiv.P(a, b) * aiv.A(b, i);
      aiv.S(a, i) = v;
    }
  }
  aiv.Ht.noalias() = aiv.S.transpose() * g.G.transpose();
  return true;
}

/// σ_ss,q, b_q and σ_acc,q of a subset from its projection S^(k) (rows 0..2) and S^(0) (ADD Eq. 21).
void setSubsetErrors(SubsetSolution& s, const Eigen::MatrixXd& S0, const Geometry& g, const Eigen::VectorXd& c_acc) {
  for (int q = 0; q < 3; ++q) {
    double ss = 0.0, b = 0.0, acc = 0.0;
    for (int i = 0; i < g.numSats(); ++i) {
      const double sk = s.S(q, i), d = sk - S0(q, i);
      ss += d * d * c_acc[i];  // ADD Eq. 21 (C_acc)
      b += std::abs(sk) * g.bnom[i];
      acc += sk * sk * c_acc[i];
    }
    s.sigma_ss[q] = std::sqrt(ss);
    s.bias[q] = b;
    s.sigma_acc[q] = std::sqrt(acc);
  }
}

/// The subset without satellite i from the all-in-view solution by a rank-one down-date
/// (Sherman–Morrison on N_k = N − w_i g_i g_iᵀ): with H_ij = g_iᵀ S_·j (the hat matrix, h_i = H_ii),
///   S^(k)_qj = S_qj + S_qi H_ij / (1 − h_i) for j ≠ i, 0 for j = i;
///   σ_q^(k)2 = P_qq + S_qi² / (w_i (1 − h_i));
/// and, in the same pass, setSubsetErrors' sums. False when 1 − h_i < kMinDowndateRedundancy:
/// the caller solves the subset from its own normal matrix.
bool downdatedSubsetSolution(const Geometry& g, const AllInView& aiv, const Eigen::MatrixXd& S0,
                             const Eigen::VectorXd& c_acc, int i, SubsetSolution& out) {
  const int n = g.numSats(), m = g.numStates();
  double h = 0.0;
  for (int a = 0; a < m; ++a) h += g.G(i, a) * aiv.S(a, i);  // h_i = g_iᵀ S_·i, the leverage
  const double redundancy = 1.0 - h;
  if (!(redundancy >= kMinDowndateRedundancy)) return false;
  const double si[3] = {aiv.S(0, i), aiv.S(1, i), aiv.S(2, i)};
  double ss[3] = {0, 0, 0}, b[3] = {0, 0, 0}, acc[3] = {0, 0, 0};
  out.S.resize(3, n);
  const double* h_i = aiv.Ht.col(i).data();  // row i of the hat matrix
  for (int j = 0; j < n; ++j) {
    const double f = j == i ? 0.0 : h_i[j] / redundancy;
    for (int q = 0; q < 3; ++q) {
      const double sk = j == i ? 0.0 : aiv.S(q, j) + si[q] * f, d = sk - S0(q, j);
      out.S(q, j) = sk;
      ss[q] += d * d * c_acc[j];
      b[q] += std::abs(sk) * g.bnom[j];
      acc[q] += sk * sk * c_acc[j];
    }
  }
  const double c = g.sigma_int[i] * g.sigma_int[i] / redundancy;  // 1 / (w_i (1 − h_i))
  for (int q = 0; q < 3; ++q) {
    out.sigma[q] = std::sqrt(aiv.P(q, q) + si[q] * si[q] * c);
    out.sigma_ss[q] = std::sqrt(ss[q]);
    out.bias[q] = b[q];
    out.sigma_acc[q] = std::sqrt(acc[q]);
  }
  return std::isfinite(out.sigma[0]) && std::isfinite(out.sigma[2]);
}

/// Why ARAIM cannot run on this geometry (too few satellites, a constellation with a single
/// one), or nothing.
std::optional<std::string> geometryShortfall(const Geometry& g) {
  const int n = g.numSats(), m = g.numStates();
  if (n < m + 1) {
    return "too few satellites: " + std::to_string(n) + " in view, ARAIM needs at least " + std::to_string(m + 1) +
           " for " + std::to_string(m) + " unknowns (3 + one clock per constellation)";
  }
  for (Constellation c : g.clocks) {
    const auto count = std::count_if(g.sats.begin(), g.sats.end(), [&](const SatId& s) { return s.constellation == c; });
    if (count == 1) {
      return std::string("constellation ") + constellationName(c) +
             " has a single satellite: it only fixes its own clock and cannot be checked";
    }
  }
  return std::nullopt;
}

AllInView allInView(const Geometry& g) {
  AllInView aiv;
  const int m = g.numStates();
  aiv.A.resize(m, g.numSats());
  for (int i = 0; i < g.numSats(); ++i) {
    const double w = 1.0 / (g.sigma_int[i] * g.sigma_int[i]);
    for (int a = 0; a < m; ++a) aiv.A(a, i) = g.G(i, a) * w;
  }
  aiv.N = StateMatrix::Zero(m, m);
  for (int i = 0; i < g.numSats(); ++i) {  // N = Σ w_i g_i g_iᵀ, without Eigen's general product kernel
    for (int a = 0; a < m; ++a) {
      for (int b = 0; b <= a; ++b) aiv.N(a, b) += aiv.A(a, i) * g.G(i, b);
    }
  }
  return aiv;
}

/// The all-in-view projection, sigmas, nominal biases and vertical accuracy sigma.
void setAllInViewErrors(AraimResult& out, const Geometry& g, SubsetSolution&& all, const Eigen::VectorXd& c_acc) {
  out.S0 = std::move(all.S);
  for (int q = 0; q < 3; ++q) {
    out.sigma0[q] = all.sigma[q];
    out.bias0[q] = out.S0.row(q).cwiseAbs().dot(g.bnom);  // b_q^(0) = Σ|S_q,i| b_nom,i
  }
  out.sigma_acc_v_m = std::sqrt(out.S0.row(2).cwiseAbs2().dot(c_acc));
}

}  // namespace

/// Fault modes from the ISM.
FaultModeSet araimFaultModes(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg) {
  std::vector<Constellation> cons;
  std::vector<double> p_sat;
  cons.reserve(g.sats.size());
  p_sat.reserve(g.sats.size());
  for (const SatId& s : g.sats) {
    cons.push_back(s.constellation);
    p_sat.push_back(model.of(s.constellation).psat);
  }
  std::vector<double> p_const(kNumConstellations);
  for (Constellation c : kAllConstellations) p_const[static_cast<std::size_t>(c)] = model.of(c).pconst;
  FaultModeOptions o;
  o.rule = cfg.rule;
  o.p_thres = cfg.requirements.p_thres;
  o.phmi = cfg.requirements.phmi_vert + cfg.requirements.phmi_hor;
  o.fc_thres = cfg.fc_thres;
  return determineFaultModes(cons, p_sat, p_const, o);
}

namespace {

/// One subset solution per monitorable fault mode; an unmonitorable mode's prior goes to the
/// unmonitored probability.
void monitorFaultModes(AraimResult& out, const Geometry& g, const AllInView& aiv, FaultModeSet&& fm,
                       const Eigen::VectorXd& c_acc) {
  out.n_fault_max = fm.n_fault_max;
  out.p_not_monitored = fm.p_not_monitored;
  out.subsets.reserve(fm.modes.size());
  for (FaultMode& mode : fm.modes) {
    SubsetSolution s;
    s.removed = std::move(mode.removed);
    s.prior = mode.prior;
    s.event_prior = mode.event_prior;
    const bool downdated = s.removed.size() == 1 && aiv.S.size() > 0 &&
                           downdatedSubsetSolution(g, aiv, out.S0, c_acc, s.removed[0], s);
    out.downdated_modes += downdated ? 1 : 0;
    if (!downdated) {
      if (!subsetSolution(g, aiv, s.removed, s)) {
        out.p_not_monitored += mode.prior;  // unmonitorable: its whole prior is integrity risk
        ++out.unmonitorable_modes;
        continue;
      }
      setSubsetErrors(s, out.S0, g, c_acc);
    }
    out.subsets.push_back(std::move(s));
  }
}

/// Solution separation thresholds of every subset.
void setThresholds(AraimResult& out, const Requirements& req) {
  out.fault_modes = static_cast<int>(out.subsets.size());
  const double nfm = std::max(1, out.fault_modes);
  out.k_fa_h = normalTailInverse(req.pfa_hor / (4.0 * nfm));   // ADD Eq. 26
  out.k_fa_v = normalTailInverse(req.pfa_vert / (2.0 * nfm));  // ADD Eq. 27
  for (SubsetSolution& s : out.subsets) {
    s.threshold = {out.k_fa_h * s.sigma_ss[0], out.k_fa_h * s.sigma_ss[1], out.k_fa_v * s.sigma_ss[2]};
  }
}

/// Protection levels per axis and the EMT; false (with the reason) when the unmonitored
/// probability leaves no budget.
bool solveProtectionLevels(AraimResult& out, const Requirements& req) {
  // Risk budgets (ADD Eq. 31–32): the unmonitored probability is taken off the top; an outcome
  // of FDE gets the share ρ of what is left (MAAST for ARAIM's rho_j).
  const double scale = out.budget_share * (1.0 - out.p_not_monitored / (req.phmi_vert + req.phmi_hor));
  if (!(scale > 0.0)) {
    out.reason = "the unmonitored fault probability " + std::to_string(out.p_not_monitored) +
                 " exceeds the integrity budget";
    return false;
  }
  const double budget_v = req.phmi_vert * scale;
  const double budget_h = 0.5 * req.phmi_hor * scale;  // per horizontal axis
  std::array<double, 3> pl{}, pl_eq{};
  std::vector<RiskTerm> terms;
  terms.reserve(out.subsets.size() + 1);
  for (int q = 0; q < 3; ++q) {
    terms.clear();
    terms.push_back({2.0, 0.0, out.bias0[q], out.sigma0[q]});
    for (const SubsetSolution& s : out.subsets) terms.push_back({s.prior, s.threshold[q], s.bias[q], s.sigma[q]});
    pl[q] = solveProtectionLevel(terms, q == 2 ? budget_v : budget_h, req.tol_pl_m, &pl_eq[q],
                                 &out.initial_bracket[static_cast<std::size_t>(q)]);
  }
  out.hpl_axis_m = {pl[0], pl[1]};
  out.hpl_m = std::hypot(pl[0], pl[1]);
  out.vpl_m = pl[2];
  out.hpl_equal_allocation_m = std::hypot(pl_eq[0], pl_eq[1]);
  out.vpl_equal_allocation_m = pl_eq[2];
  return true;
}

/// EMT (ADD Eq. 35): the largest vertical threshold among monitored modes whose probability is
/// at least P_EMT — by default the mode's own prior, as MAAST for ARAIM compares it.
void setEffectiveMonitorThreshold(AraimResult& out, const AraimConfig& cfg) {
  out.emt_m = 0.0;
  for (const SubsetSolution& s : out.subsets) {
    const double p = cfg.emt_probability == EmtProbability::kModePrior ? s.prior : s.event_prior;
    if (p >= cfg.requirements.p_emt) out.emt_m = std::max(out.emt_m, s.threshold[2]);
  }
}

/// Available when the levels are within the alert limits (and, unless horizontal only, the EMT
/// and the accuracy within theirs); else the first limit exceeded is the reason.
void judgeAvailability(AraimResult& out, const AraimConfig& cfg) {
  const Requirements& req = cfg.requirements;
  if (cfg.horizontal_only) {
    out.available = out.hpl_m <= req.hal_m;
    if (!out.available) out.reason = "HPL exceeds HAL";
    return;
  }
  out.available = out.vpl_m <= req.val_m && out.hpl_m <= req.hal_m && out.emt_m <= req.emt_m &&
                  out.sigma_acc_v_m <= req.sigma_acc_m;
  if (!out.available) {
    out.reason = out.vpl_m > req.val_m     ? "VPL exceeds VAL"
                 : out.hpl_m > req.hal_m   ? "HPL exceeds HAL"
                 : out.emt_m > req.emt_m   ? "EMT exceeds its limit"
                                           : "sigma_acc exceeds its limit";
  }
}

}  // namespace

RiskAndSlope integrityRiskAndSlope(const std::vector<RiskTerm>& terms, double pl) {
  RiskAndSlope out;
  for (const RiskTerm& t : terms) {
    const double z = (pl - t.threshold - t.bias) / t.sigma;
    if (z < 0.0) {
      out.risk += t.prior;  // Q̃ = 1, flat
      continue;
    }
    const TailAndDensity q = normalTailAndDensity(z);  // one exponential for both
    out.risk += t.prior * q.tail;
    out.slope -= t.prior * q.density / t.sigma;
  }
  return out;
}

double integrityRisk(const std::vector<RiskTerm>& terms, double pl) {
  double r = 0.0;
  for (const RiskTerm& t : terms) r += t.prior * modifiedTail((pl - t.threshold - t.bias) / t.sigma);
  return r;
}

double solveProtectionLevel(const std::vector<RiskTerm>& terms, double budget, double tol, double* equal_allocation,
                            PlBracket* initial) {
  const double n1 = static_cast<double>(terms.size());
  double low = -1e300, high = -1e300;
  // Modes of one kind share a prior (every single satellite of a constellation …): the
  // multipliers are reused while the prior repeats (the same values, not an approximation).
  double last_prior = -1.0, k_low = 0.0, k_high = 0.0;
  for (const RiskTerm& t : terms) {
    if (t.prior != last_prior) {
      last_prior = t.prior;
      k_low = t.prior > budget ? normalTailInverse(budget / t.prior) : 0.0;
      const double share = budget / (n1 * t.prior);
      k_high = share < 0.5 ? normalTailInverse(share) : 0.0;
    }
    if (t.prior > budget) low = std::max(low, t.threshold + t.bias + k_low * t.sigma);
    high = std::max(high, t.threshold + t.bias + k_high * t.sigma);
  }
  if (equal_allocation) *equal_allocation = high;
  low = std::min(low, high);
  if (initial) *initial = {low, high};
  // ADD Appendix B: at `low` the largest single term already uses the whole budget; at `high`
  // every term uses at most budget/(N+1). The risk decreases with PL in between. The bracket is
  // shrunk to ≤ tol by a safeguarded Newton iteration (each evaluated point replaces `low` or
  // `high`; a Newton step that leaves the bracket is replaced by the midpoint), and the upper
  // end returned — the same guarantee as plain bisection in fewer risk evaluations.
  double x = high;
  while (high - low > tol) {
    const RiskAndSlope rs = integrityRiskAndSlope(terms, x);
    (rs.risk > budget ? low : high) = x;
    if (high - low <= tol) break;
    double next = 0.5 * (low + high);
    if (rs.slope < 0.0 && rs.risk > 0.0) {
      // Newton on ln(risk): the risk falls about exponentially in PL, so its logarithm is
      // nearly linear and the step lands near the root from far away.
      const double step = std::log(rs.risk / budget) * rs.risk / -rs.slope;
      // Once the step is below tol/2 the estimate is that close to the root: the next point
      // goes tol/2 past it, on the side whose end of the bracket has not moved yet.
      const double newton = x + step + (std::abs(step) < 0.5 * tol ? std::copysign(0.5 * tol, step) : 0.0);
      if (newton > low && newton < high) next = newton;
    }
    x = next;
  }
  return high;
}

AraimResult araimProtectionLevels(const Geometry& g, const ErrorModel& model, const AraimConfig& cfg) {
  if (geometryShortfall(g)) return araimLevelsOverModes(g, FaultModeSet{}, cfg, 1.0);  // states why
  return araimLevelsOverModes(g, araimFaultModes(g, model, cfg), cfg, 1.0);
}

AraimResult araimLevelsOverModes(const Geometry& g, FaultModeSet modes, const AraimConfig& cfg, double budget_share) {
  AraimResult out;
  out.budget_share = budget_share;
  if (const std::optional<std::string> why = geometryShortfall(g)) {
    out.reason = *why;
    return out;
  }
  AllInView aiv = allInView(g);
  SubsetSolution all;
  if (cfg.subset_downdate && !modes.modes.empty() && setAllInViewCovariance(aiv, g)) {
    all.S = aiv.S.topRows(3);  // the all-in-view solution is the covariance's first three rows
    for (int q = 0; q < 3; ++q) all.sigma[q] = std::sqrt(aiv.P(q, q));
  } else if (!subsetSolution(g, aiv, {}, all)) {
    out.reason = "singular geometry: the satellites do not fix position and clocks";
    return out;
  }
  const Eigen::VectorXd c_acc = g.sigma_acc.array().square();
  setAllInViewErrors(out, g, std::move(all), c_acc);
  monitorFaultModes(out, g, aiv, std::move(modes), c_acc);
  setThresholds(out, cfg.requirements);
  setEffectiveMonitorThreshold(out, cfg);
  out.accuracy_computed = true;
  if (!solveProtectionLevels(out, cfg.requirements)) return out;
  out.pl_computed = std::isfinite(out.hpl_m) && std::isfinite(out.vpl_m);
  if (!out.pl_computed) {
    out.reason = "protection level is not finite";
    return out;
  }
  judgeAvailability(out, cfg);
  return out;
}

}  // namespace skylane::integrity
