#pragma once
/// \file
/// \brief The ADD v3.0 Appendix D example geometry (10 satellites, GPS + Galileo; EU-US ARAIM
/// Working Group, "ARAIM Airborne Algorithm Description Document") and an error model with
/// given fault priors, shared by the ARAIM and exclusion tests.

#include "integrity/gnss/error_model.hpp"
#include "integrity/raim/wls.hpp"

#include <cmath>

namespace skylane::integrity::araim_example {

/// The example's geometry with σ_URA 0.75 m, σ_URE 0.5 m and a 0.5 m nominal bias.
inline Geometry addExampleGeometry() {
  const double rows[10][5] = {{0.0225, 0.9951, -0.0966, 1, 0},   {0.6750, -0.6900, -0.2612, 1, 0},
                              {0.0723, -0.6601, -0.7477, 1, 0},  {-0.9398, 0.2553, -0.2269, 1, 0},
                              {-0.5907, -0.7539, -0.2877, 1, 0}, {-0.3236, -0.0354, -0.9455, 0, 1},
                              {-0.6748, 0.4356, -0.5957, 0, 1},  {0.0938, -0.7004, -0.7075, 0, 1},
                              {0.5571, 0.3088, -0.7709, 0, 1},   {0.6622, 0.6958, -0.2780, 0, 1}};
  const double c_int[10] = {3.8865, 1.4377, 0.8604, 1.6383, 1.3229, 0.8434, 0.8963, 0.8669, 0.8573, 1.3616};
  Geometry g;
  g.G.resize(10, 5);
  g.sigma_int.resize(10);
  g.sigma_acc.resize(10);
  g.bnom = Eigen::VectorXd::Constant(10, 0.5);
  g.clocks = {Constellation::kGps, Constellation::kGalileo};
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 5; ++j) g.G(i, j) = rows[i][j];
    g.sigma_int[i] = std::sqrt(c_int[i]);
    g.sigma_acc[i] = std::sqrt(c_int[i] - (0.75 * 0.75 - 0.5 * 0.5));  // σ_URA 0.75 → σ_URE 0.5
    g.sats.push_back({i < 5 ? Constellation::kGps : Constellation::kGalileo, i % 5 + 1});
    g.elevation_rad.push_back(0.5);
  }
  return g;
}

/// An error model with the same satellite and constellation fault priors for every constellation.
inline ErrorModel ismWith(double psat, double pconst) {
  ErrorModel m;
  for (Constellation c : kAllConstellations) {
    m.of(c).psat = psat;
    m.of(c).pconst = pconst;
  }
  return m;
}

}  // namespace skylane::integrity::araim_example
