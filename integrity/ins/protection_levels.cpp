#include "integrity/ins/protection_levels.hpp"

#include "integrity/stats.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace skylane::integrity::ins {

namespace {

/// Position-and-clock columns of H (n × 4).
Eigen::MatrixXd positionClockColumns(const GnssUpdateRecord& rec) {
  Eigen::MatrixXd Hpc(rec.H.rows(), 4);
  Hpc.leftCols<3>() = rec.H.middleCols<3>(kPos);
  Hpc.col(3) = rec.H.col(kClock);
  return Hpc;
}

/// Q⁻¹(p), remembered: the same few probabilities recur every epoch (they depend only on the
/// number of satellites and the configuration), and the inverse costs ~0.3 µs.
double tailInverse(double p) {
  thread_local std::unordered_map<double, double> cache;
  const auto it = cache.find(p);
  if (it != cache.end()) return it->second;
  if (cache.size() > 4096) cache.clear();
  const double k = normalTailInverse(p);
  cache.emplace(p, k);
  return k;
}

/// Q⁻¹(p/2) for a two-sided bound; 0 when the mode's risk needs no bound.
double twoSidedK(double p) { return p >= 1.0 ? 0.0 : tailInverse(p / 2.0); }

}  // namespace

double imuInnovationStatistic(const GnssUpdateRecord& rec) {
  if (!rec.ok || rec.H.rows() < 4) return -1.0;
  const Eigen::MatrixXd Hpc = positionClockColumns(rec);
  const Eigen::MatrixXd& SiH = rec.S_inv_Hpc;
  const Eigen::Matrix4d info = Hpc.transpose() * SiH;  // (G S Gᵀ)⁻¹ = H_pcᵀ S⁻¹ H_pc
  const Eigen::Vector4d b = info.ldlt().solve(SiH.transpose() * rec.innovation);  // G ν
  return b.dot(info * b);
}

namespace {

/// What every fault mode's protection level is built from (ENU axes).
struct FaultModeTerms {
  Eigen::Vector3d a_nu;       ///< A ν, A = G_p − K_p: the GNSS-only minus the filter's update
  Eigen::Matrix3d cov_ff;     ///< fault-free position covariance
  Eigen::Matrix3d cov_i;      ///< covariance of the GNSS-only solution's difference
  Eigen::Vector3d bias_ff;    ///< fault-free bias bound
  Eigen::Vector3d bias_i;     ///< bias bound under a fault
  Eigen::Vector3d max_slope;  ///< largest LSR characteristic slope per axis
};

/// Characteristic slope per axis of the LSR test on the same measurements, the largest over
/// the satellites: |G_p,qm| σ_m / √s_mm, with the residual matrix S_res = I − H (Hᵀ W H)⁻¹ Hᵀ W
/// of which only the diagonal s_mm = 1 − w_m h_m (Hᵀ W H)⁻¹ h_mᵀ is needed.
Eigen::Vector3d maxLsrSlopes(const GnssUpdateRecord& rec, const Eigen::MatrixXd& Hpc, const Eigen::MatrixXd& Gp) {
  const int n = static_cast<int>(rec.H.rows());
  const Eigen::VectorXd w = rec.sigma.cwiseAbs2().cwiseInverse();
  const Eigen::Matrix4d lsr_info = Hpc.transpose() * w.asDiagonal() * Hpc;
  const Eigen::Matrix4d lsr_cov = lsr_info.inverse();
  Eigen::Matrix3Xd slope(3, n);
  for (int m = 0; m < n; ++m) {
    const Eigen::Vector4d hm = Hpc.row(m).transpose();
    const double smm = std::max(1.0 - w(m) * hm.dot(lsr_cov * hm), 1e-12);
    slope.col(m) = Gp.col(m).cwiseAbs() * (rec.sigma(m) / std::sqrt(smm));
  }
  return slope.rowwise().maxCoeff();
}

/// The terms of the update `rec`; nothing when its geometry is degenerate.
std::optional<FaultModeTerms> faultModeTerms(const GnssUpdateRecord& rec, const Eigen::MatrixXd& Hpc) {
  // G = (H_pcᵀ S⁻¹ H_pc)⁻¹ H_pcᵀ S⁻¹; A = G_p − K_p (ENU rows).
  const Eigen::MatrixXd& SiH = rec.S_inv_Hpc;
  const Eigen::Matrix4d info = Hpc.transpose() * SiH;
  const Eigen::FullPivLU<Eigen::Matrix4d> info_lu(info);
  if (!info_lu.isInvertible()) return std::nullopt;
  const Eigen::MatrixXd G = info_lu.solve(SiH.transpose());  // 4 × n
  const Eigen::MatrixXd Gp = rec.R_enu_ecef * G.topRows<3>();
  const Eigen::MatrixXd Kp = rec.R_enu_ecef * rec.K.middleRows<3>(kPos);
  const Eigen::MatrixXd A = Gp - Kp;
  FaultModeTerms t;
  t.a_nu = A * rec.innovation;
  t.cov_ff = rec.P_pos_enu;
  t.cov_i = rec.P_pos_enu + A * rec.S * A.transpose();
  const Eigen::MatrixXd M_i = rec.M_pos_enu - A * rec.N_innov;
  t.bias_ff = rec.M_pos_enu.cwiseAbs() * rec.bias_bnom;
  t.bias_i = M_i.cwiseAbs() * rec.bias_bnom;
  t.max_slope = maxLsrSlopes(rec, Hpc, Gp);
  return t;
}

/// One mode's protection level per axis, with its horizontal (bh) and vertical (bv) budgets.
void setModeAxes(ModePl& pl, InsFaultMode mode, const ModeBudget& bh, const ModeBudget& bv, const FaultModeTerms& t,
                 int dof, const FaultModeConfig& cfg) {
  for (int q = 0; q < 3; ++q) {
    const double p = q < 2 ? bh.conditional / 2.0 : bv.conditional;
    const double k = twoSidedK(p);
    if (mode == InsFaultMode::kFaultFree) {
      pl.axis_m[q] = k * std::sqrt(t.cov_ff(q, q)) + t.bias_ff(q);
      continue;
    }
    double v = std::abs(t.a_nu(q)) + k * std::sqrt(t.cov_i(q, q)) + t.bias_i(q);
    if ((mode == InsFaultMode::kGnssSingle || mode == InsFaultMode::kGnssSingleImu) && p < 1.0) {
      v += t.max_slope(q) * raimThresholds(dof, cfg.pfa_gnss, p).p_bias;
    }
    pl.axis_m[q] = v;
  }
  pl.hpl_m = std::hypot(pl.axis_m[0], pl.axis_m[1]);
  pl.vpl_m = pl.axis_m[2];
}

}  // namespace

FaultModePls faultModeProtectionLevels(const GnssUpdateRecord& rec, const FaultModeConfig& cfg) {
  FaultModePls out;
  const int n = static_cast<int>(rec.H.rows());
  if (!rec.ok || n < 5) {
    out.reason = "fewer than 5 satellites: the LSR test cannot protect the GS mode";
    return out;
  }
  const std::optional<FaultModeTerms> terms = faultModeTerms(rec, positionClockColumns(rec));
  if (!terms) {
    out.reason = "degenerate geometry";
    return out;
  }
  const RiskAllocation alloc_h = allocateRisk(n, DetectionClass::kIntegrated, false, cfg.risk);
  const RiskAllocation alloc_v = allocateRisk(n, DetectionClass::kIntegrated, true, cfg.risk);
  out.bias_estimate_up_m = terms->a_nu.z();
  out.available = true;
  out.hpl_m = 0.0;
  out.vpl_m = 0.0;
  for (int i = 0; i < kNumInsFaultModes; ++i) {
    const auto mode = static_cast<InsFaultMode>(i);
    ModePl& pl = out.modes[i];
    const ModeBudget& bh = alloc_h.of(mode);
    const ModeBudget& bv = alloc_v.of(mode);
    pl.needs_pl = bh.considered && (bh.needs_pl || bv.needs_pl);
    if (!pl.needs_pl) continue;
    setModeAxes(pl, mode, bh, bv, *terms, n - 4, cfg);
    if (pl.hpl_m > out.hpl_m) {
      out.hpl_m = pl.hpl_m;
      out.deciding_h = mode;
    }
    if (pl.vpl_m > out.vpl_m) {
      out.vpl_m = pl.vpl_m;
      out.deciding_v = mode;
    }
  }
  return out;
}

double imuErrorWeightRatio(int grade_index) {
  switch (grade_index) {
    case 0: return 1.0 / 12.0;
    case 1: return 5.0 / 12.0;
    case 2: return 9.0 / 12.0;
    default: throw std::invalid_argument("IMU grade index must be 0 (aviation), 1 (tactical) or 2 (consumer)");
  }
}

ThreeHypothesisInsMonitor::ThreeHypothesisInsMonitor(const ThreeHypothesisInsConfig& cfg) : cfg_(cfg) {
  if (cfg_.window < 1) throw std::invalid_argument("three-hypothesis INS PL: the averaging window must be ≥ 1 epoch");
  if (!(cfg_.lambda > 0.0 && cfg_.lambda < 1.0)) throw std::invalid_argument("three-hypothesis INS PL: λ must lie in (0, 1)");
}

ThreeHypothesisInsPl ThreeHypothesisInsMonitor::push(const GnssUpdateRecord& rec, const RaimPl& raim) {
  ThreeHypothesisInsPl out;
  if (!rec.ok) return out;
  const Eigen::Vector3d& c = rec.correction_enu;
  corrections_.emplace_back(std::hypot(c.x(), c.y()), std::abs(c.z()), 0.0);
  if (raim.available) mu_.emplace_back(raim.max_hslope * raim.thresholds.p_bias, raim.max_vslope * raim.thresholds.p_bias);
  while (static_cast<int>(corrections_.size()) > cfg_.window) corrections_.pop_front();
  while (static_cast<int>(mu_.size()) > cfg_.window) mu_.pop_front();
  if (!raim.available || mu_.empty()) return out;

  Eigen::Vector3d mean_corr = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : corrections_) mean_corr += v;
  mean_corr /= static_cast<double>(corrections_.size());
  Eigen::Vector2d mean_mu = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& v : mu_) mean_mu += v;
  mean_mu /= static_cast<double>(mu_.size());

  const Eigen::Matrix3d& P = rec.P_pos_enu;
  const double sigma_h = std::sqrt(P(0, 0) + P(1, 1));
  const double sigma_v = std::sqrt(P(2, 2));
  const Eigen::MatrixXd Kp = rec.R_enu_ecef * rec.K.middleRows<3>(kPos);
  const Eigen::Matrix3d cov_fault = Kp * rec.S * Kp.transpose();
  const double sigma_fault_h = std::sqrt(cov_fault(0, 0) + cov_fault(1, 1));
  const double sigma_fault_v = std::sqrt(cov_fault(2, 2));

  const double lam = cfg_.lambda;
  out.hpl_nominal_m = tailInverse(lam * cfg_.share[0] * cfg_.phmi_h) * sigma_h;
  out.vpl_nominal_m = tailInverse(lam * cfg_.share[0] * cfg_.phmi_v) * sigma_v;
  out.hpl_imu_fault_m = tailInverse(lam * cfg_.share[1] * cfg_.phmi_h) * sigma_fault_h + mean_corr.x();
  out.vpl_imu_fault_m = tailInverse(lam * cfg_.share[1] * cfg_.phmi_v) * sigma_fault_v + mean_corr.y();
  out.hpl_gnss_fault_m = mean_mu.x() + tailInverse(cfg_.share[2] * cfg_.phmi_h / 2.0) * sigma_h;
  out.vpl_gnss_fault_m = mean_mu.y() + tailInverse(cfg_.share[2] * cfg_.phmi_v / 2.0) * sigma_v;
  out.hpl_m = std::max({out.hpl_nominal_m, out.hpl_imu_fault_m, out.hpl_gnss_fault_m});
  out.vpl_m = std::max({out.vpl_nominal_m, out.vpl_imu_fault_m, out.vpl_gnss_fault_m});
  out.available = true;
  return out;
}

}  // namespace skylane::integrity::ins
