#include "integrity/raim/wls.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace skylane::integrity {
namespace {

/// Reciprocal condition below which GᵀWG counts as singular (a degenerate sky): far above
/// the 1e-16 of double round-off so the covariance is still meaningful.
constexpr double kMinRcond = 1e-12;

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
  if (n < m || m == 0) return out;
  const Eigen::VectorXd w = sigma.array().square().inverse();
  const Eigen::MatrixXd GtW = G.transpose() * w.asDiagonal();
  const Eigen::MatrixXd N = GtW * G;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(N);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > kMinRcond)) return out;
  out.P = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
  out.S = out.P * GtW;
  out.ok = out.S.allFinite();
  return out;
}

}  // namespace skylane::integrity
