#pragma once
/// \file
/// \brief Line-of-sight geometry and weighted least squares (the linearised GNSS position
/// problem y = G·x + ε, ε ~ N(0, W⁻¹); Kaplan & Hegarty, "Understanding GPS/GNSS", 3rd ed., §7.3).

#include "integrity/gnss/error_model.hpp"
#include "integrity/gnss/satellite_id.hpp"

#include "maps/geodesy.hpp"

#include <Eigen/Core>

#include <vector>

namespace skylane::integrity {

/// \brief One satellite as seen from the user.
struct SatLook {
  SatId sat;
  maps::LookAngles look;
};

/// \brief A linearised geometry in the local ENU frame: rows [−u_E, −u_N, −u_U, clock one-hot],
/// one clock column per constellation present; with per-satellite error budgets.
struct Geometry {
  std::vector<SatId> sats;
  std::vector<double> elevation_rad;
  Eigen::MatrixXd G;          ///< n × (3 + n_clocks)
  Eigen::VectorXd sigma_int;  ///< σ_int,i [m]
  Eigen::VectorXd sigma_acc;  ///< σ_acc,i [m]
  Eigen::VectorXd bnom;       ///< b_nom,i [m]
  std::vector<Constellation> clocks;  ///< constellation of each clock column

  [[nodiscard]] int numSats() const { return static_cast<int>(sats.size()); }
  [[nodiscard]] int numStates() const { return static_cast<int>(G.cols()); }
  /// \brief Copy without satellite `index` (a clock column left empty is removed).
  [[nodiscard]] Geometry without(int index) const;
};

/// \brief Builds the geometry (G, σ's) for satellites at the given look angles.
/// \param tau_vert_m single-frequency ionospheric bound (ignored for dual frequency).
[[nodiscard]] Geometry buildGeometry(const std::vector<SatLook>& sats, const ErrorModel& model,
                                     double tau_vert_m);

/// \brief The weighted least-squares solution operator and covariance.
struct WlsSolution {
  bool ok = false;        ///< false when GᵀWG is singular (too few satellites, degenerate sky)
  Eigen::MatrixXd S;      ///< (GᵀWG)⁻¹GᵀW, states × n
  Eigen::MatrixXd P;      ///< (GᵀWG)⁻¹, the state covariance
};

/// \brief Solves for S and P with weights W = diag(1/σ²).
[[nodiscard]] WlsSolution solveWls(const Eigen::MatrixXd& G, const Eigen::VectorXd& sigma);

}  // namespace skylane::integrity
