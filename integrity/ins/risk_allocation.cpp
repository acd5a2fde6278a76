#include "integrity/ins/risk_allocation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <map>
#include <string>
#include <tuple>

namespace skylane::integrity {

std::string_view faultModeName(InsFaultMode m) {
  switch (m) {
    case InsFaultMode::kFaultFree: return "FF";
    case InsFaultMode::kGnssSingle: return "GS";
    case InsFaultMode::kGnssMulti: return "GM";
    case InsFaultMode::kImu: return "I";
    case InsFaultMode::kGnssSingleImu: return "GSI";
    case InsFaultMode::kGnssMultiImu: return "GMI";
  }
  return "?";
}

namespace {

void requireProbability(double p, const char* name) {
  if (!(p >= 0.0 && p < 1.0)) {
    throw std::invalid_argument(std::string("risk allocation: ") + name + " must lie in [0, 1), got " +
                                std::to_string(p));
  }
}

/// Σ_{j≥2} C(K,j) p^j (1−p)^(K−j), summed term by term (no 1 − P0 − P1 cancellation).
double multiFaultPrior(int k, double p) {
  double sum = 0.0;
  double binom = 1.0;  // C(K, j)
  for (int j = 1; j <= k; ++j) {
    binom = binom * (k - j + 1) / j;
    if (j >= 2) sum += binom * std::pow(p, j) * std::pow(1.0 - p, k - j);
  }
  return sum;
}

RiskAllocation computeAllocation(int num_sats, DetectionClass detection, bool vertical,
                                 const RiskAllocationConfig& cfg);

}  // namespace

std::array<double, kNumInsFaultModes> faultModePriors(int num_sats, DetectionClass detection,
                                                      const RiskAllocationConfig& cfg) {
  if (num_sats < 1) {
    throw std::invalid_argument("risk allocation: the number of satellites must be ≥ 1, got " +
                                std::to_string(num_sats));
  }
  requireProbability(cfg.p_sat, "p_sat");
  requireProbability(cfg.p_imu, "p_imu");
  const double p = cfg.p_sat;
  const double none = std::pow(1.0 - p, num_sats);                   // Eq. (4): no satellite faulty
  const double single = num_sats * p * std::pow(1.0 - p, num_sats - 1);  // exactly one
  const double multi = multiFaultPrior(num_sats, p);                 // two or more
  std::array<double, kNumInsFaultModes> priors{};
  auto set = [&priors](InsFaultMode m, double v) { priors[static_cast<int>(m)] = v; };
  if (detection == DetectionClass::kGnssAlone) {
    set(InsFaultMode::kFaultFree, none);
    set(InsFaultMode::kGnssSingle, single);
    set(InsFaultMode::kGnssMulti, multi);
    return priors;
  }
  const double imu_ok = 1.0 - cfg.p_imu;  // Eq. (7): GNSS and IMU faults independent
  set(InsFaultMode::kFaultFree, none * imu_ok);
  set(InsFaultMode::kGnssSingle, single * imu_ok);
  set(InsFaultMode::kGnssMulti, multi * imu_ok);
  set(InsFaultMode::kImu, none * cfg.p_imu);
  set(InsFaultMode::kGnssSingleImu, single * cfg.p_imu);
  if (cfg.include_gm_imu) set(InsFaultMode::kGnssMultiImu, multi * cfg.p_imu);
  return priors;
}

RiskAllocation allocateRisk(int num_sats, DetectionClass detection, bool vertical, const RiskAllocationConfig& cfg) {
  // Remembered per thread: a navigator asks for the same few allocations every epoch.
  using Key = std::tuple<int, int, bool, double, double, double, double, double, bool>;
  thread_local std::map<Key, RiskAllocation> cache;
  const Key key{num_sats, static_cast<int>(detection), vertical, cfg.i_req, cfg.vertical_share, cfg.p_sat, cfg.p_imu,
                cfg.negligible_fraction, cfg.include_gm_imu};
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  RiskAllocation out = computeAllocation(num_sats, detection, vertical, cfg);
  if (cache.size() > 1024) cache.clear();
  cache.emplace(key, out);
  return out;
}

namespace {

RiskAllocation computeAllocation(int num_sats, DetectionClass detection, bool vertical,
                                 const RiskAllocationConfig& cfg) {
  if (!(cfg.i_req > 0.0 && cfg.i_req < 1.0) || !(cfg.vertical_share > 0.0 && cfg.vertical_share < 1.0) ||
      !(cfg.negligible_fraction > 0.0 && cfg.negligible_fraction < 1.0)) {
    throw std::invalid_argument("risk allocation: i_req, vertical_share and negligible_fraction must lie in (0, 1)");
  }
  const auto priors = faultModePriors(num_sats, detection, cfg);
  RiskAllocation out;
  out.detection = detection;
  out.num_sats = num_sats;
  out.direction_budget = cfg.i_req * (vertical ? cfg.vertical_share : 1.0 - cfg.vertical_share);
  const bool integrated = detection == DetectionClass::kIntegrated;
  double left = out.direction_budget;
  int sharing = 0;
  for (int i = 0; i < kNumInsFaultModes; ++i) {
    const auto mode = static_cast<InsFaultMode>(i);
    ModeBudget& b = out.modes[i];
    const bool imu_mode = mode == InsFaultMode::kImu || mode == InsFaultMode::kGnssSingleImu ||
                          mode == InsFaultMode::kGnssMultiImu;
    b.considered = (integrated || !imu_mode) && (mode != InsFaultMode::kGnssMultiImu || cfg.include_gm_imu);
    if (!b.considered) continue;
    b.prior = priors[i];
    // §2: "far smaller" = not more than 1/20 of the total requirement; the fault-free mode always
    // needs a protection level.
    if (mode != InsFaultMode::kFaultFree && b.prior <= cfg.negligible_fraction * cfg.i_req) {
      b.needs_pl = false;
      b.budget = b.prior;
      left -= b.prior;
    } else {
      b.needs_pl = true;
      ++sharing;
    }
  }
  if (left <= 0.0) {
    throw std::invalid_argument("risk allocation: the negligible modes' priors exceed the direction's budget");
  }
  for (ModeBudget& b : out.modes) {
    if (!b.considered) continue;
    if (b.needs_pl) b.budget = left / sharing;
    b.conditional = b.prior > 0.0 ? std::min(1.0, b.budget / b.prior) : 1.0;
  }
  return out;
}

}  // namespace

}  // namespace skylane::integrity
