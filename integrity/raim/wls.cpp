#include "integrity/raim/wls.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace skylane::integrity {
namespace {

/// Reciprocal condition below which GᵀWG counts as singular (a degenerate sky): far above
/// the 1e-16 of double round-off so the covariance is still meaningful.
constexpr double kMinRcond = 1e-12;

/// Position and one clock per constellation: the most unknowns a geometry has.
constexpr int kMaxStates = 3 + kNumConstellations;

/// GᵀWG and its inverse, on the stack (no allocation per solve).
using NormalMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStates, kMaxStates>;

/// The reciprocal condition number of N in the 1-norm, 1 / (‖N‖₁ ‖N⁻¹‖₁), from its computed
/// inverse: exact where an estimate (Hager's, as Eigen's LDLT::rcond) can only be larger; NaN
/// when the inverse is not finite, 0 for a zero matrix.
double reciprocalCondition(const NormalMatrix& N, const NormalMatrix& P) {
  const double norm_n = N.cwiseAbs().colwise().sum().maxCoeff();
  const double norm_p = P.cwiseAbs().colwise().sum().maxCoeff();
  if (!(norm_n > 0.0) || !(norm_p > 0.0)) return 0.0;
  return 1.0 / (norm_n * norm_p);
}

}  // namespace

Geometry buildGeometry(const std::vector<SatLook>& sats, const ErrorModel& model, double tau_vert_m) {
  Geometry g;
  for (const SatLook& s : sats) {
    if (std::find(g.clocks.begin(), g.clocks.end(), s.sat.constellation) == g.clocks.end()) {
      g.clocks.push_back(s.sat.constellation);
    }
  }
  std::sort(g.clocks.begin(), g.clocks.end());
  const int n = static_cast<int>(sats.size());
  g.sats.reserve(sats.size());
  g.elevation_rad.reserve(sats.size());
  g.G = Eigen::MatrixXd::Zero(n, 3 + static_cast<int>(g.clocks.size()));
  g.sigma_int.resize(n);
  g.sigma_acc.resize(n);
  g.bnom.resize(n);
  for (int i = 0; i < n; ++i) {
    const SatLook& s = sats[static_cast<std::size_t>(i)];
    if (!std::isfinite(s.look.azimuth_rad) || !std::isfinite(s.look.elevation_rad)) {
      throw std::invalid_argument("satellite " + s.sat.str() + " has a non-finite azimuth or elevation");
    }
    const Eigen::Vector3d u = maps::losEnu(s.look);
    g.G.block<1, 3>(i, 0) = -u.transpose();
    const auto col = std::find(g.clocks.begin(), g.clocks.end(), s.sat.constellation) - g.clocks.begin();
    g.G(i, 3 + static_cast<int>(col)) = 1.0;
    const RangeSigma rs = rangeSigma(model, s.sat.constellation, s.look.elevation_rad, tau_vert_m);
    g.sigma_int[i] = rs.sigma_int_m;
    g.sigma_acc[i] = rs.sigma_acc_m;
    g.bnom[i] = rs.bnom_m;
    g.sats.push_back(s.sat);
    g.elevation_rad.push_back(s.look.elevation_rad);
  }
  return g;
}

Geometry Geometry::without(int index) const {
  Geometry g;
  const int n = numSats();
  std::vector<int> keep;
  for (int i = 0; i < n; ++i) {
    if (i != index) keep.push_back(i);
  }
  for (Constellation c : clocks) {
    const bool used = std::any_of(keep.begin(), keep.end(),
                                  [&](int i) { return sats[static_cast<std::size_t>(i)].constellation == c; });
    if (used) g.clocks.push_back(c);
  }
  const int m = static_cast<int>(keep.size());
  g.sats.reserve(keep.size());
  g.elevation_rad.reserve(keep.size());
  g.G = Eigen::MatrixXd::Zero(m, 3 + static_cast<int>(g.clocks.size()));
  g.sigma_int.resize(m);
  g.sigma_acc.resize(m);
  g.bnom.resize(m);
  for (int r = 0; r < m; ++r) {
    const int i = keep[static_cast<std::size_t>(r)];
    g.G.block(r, 0, 1, 3) = G.block(i, 0, 1, 3);
    const auto col = std::find(g.clocks.begin(), g.clocks.end(), sats[static_cast<std::size_t>(i)].constellation) -
                     g.clocks.begin();
    g.G(r, 3 + static_cast<int>(col)) = 1.0;
    g.sigma_int[r] = sigma_int[i];
    g.sigma_acc[r] = sigma_acc[i];
    g.bnom[r] = bnom[i];
    g.sats.push_back(sats[static_cast<std::size_t>(i)]);
    g.elevation_rad.push_back(elevation_rad[static_cast<std::size_t>(i)]);
  }
  return g;
}

WlsSolution solveWls(const Eigen::MatrixXd& G, const Eigen::VectorXd& sigma) {
  WlsSolution out;
  const int n = static_cast<int>(G.rows()), m = static_cast<int>(G.cols());
  if (m > kMaxStates) throw std::invalid_argument("solveWls: " + std::to_string(m) + " unknowns, at most " + std::to_string(kMaxStates));
  if (n < m || m == 0) return out;
  const Eigen::MatrixXd GtW = G.transpose() * sigma.array().square().inverse().matrix().asDiagonal();
  const NormalMatrix N = GtW * G;
  const Eigen::LDLT<NormalMatrix> ldlt(N);
  // GᵀWG of a geometry that fixes every unknown is positive definite: every pivot positive.
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return out;
  const NormalMatrix P = ldlt.solve(NormalMatrix::Identity(m, m));
  if (!(reciprocalCondition(N, P) > kMinRcond)) return out;
  out.P = P;
  out.S = P * GtW;
  out.ok = out.S.allFinite();
  return out;
}

}  // namespace skylane::integrity
