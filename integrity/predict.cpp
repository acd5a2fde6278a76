#include "integrity/predict.hpp"

#include "integrity/gnss/atmosphere.hpp"

#include <Eigen/Cholesky>

#include <cmath>
#include <limits>

namespace skylane::integrity {

Dops computeDops(const Geometry& g) {
  Dops d;
  const double inf = std::numeric_limits<double>::infinity();
  if (g.numSats() < g.numStates() || g.numStates() == 0) return {inf, inf, inf, inf};
  const WlsSolution w = solveWls(g.G, Eigen::VectorXd::Ones(g.numSats()));
  if (!w.ok) return {inf, inf, inf, inf};
  d.gdop = std::sqrt(w.P.trace());
  d.pdop = std::sqrt(w.P(0, 0) + w.P(1, 1) + w.P(2, 2));
  d.hdop = std::sqrt(w.P(0, 0) + w.P(1, 1));
  d.vdop = std::sqrt(w.P(2, 2));
  return d;
}

PredictSample predictAt(const OrbitSource& orbits, const PredictRequest& req, const GpsTime& t, IntegrityMethod method) {
  const Eigen::Vector3d p_user = maps::geodeticToEcef(req.place);
  const double tau = req.model.iono_tau_vert_m.value_or(ionoTauVert_m(geomagneticLatitude(req.place)));
  PredictSample s;
  s.t = t;
  for (const VisibleSatellite& v : orbits.visible(p_user, s.t, req.mask_rad)) {
    if (req.sky_mask && !req.sky_mask->isVisible(v.look)) {
      ++s.blocked;
      continue;
    }
    s.sats.push_back({v.sat, v.look});
  }
  const Geometry g = buildGeometry(s.sats, req.model, tau);
  s.dops = computeDops(g);
  s.pl = protectionLevels(g, method, req.model, req.raim, req.araim, req.with_exclusion);
  return s;
}

std::vector<PredictSample> predictIntegrity(const OrbitSource& orbits, const PredictRequest& req, IntegrityMethod method,
                                            const std::function<void(std::size_t, std::size_t)>& progress) {
  const auto n = static_cast<std::size_t>(std::floor(req.duration_s / req.step_s + 1e-9)) + 1;
  std::vector<PredictSample> out;
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    out.push_back(predictAt(orbits, req, req.start.plus(static_cast<double>(k) * req.step_s), method));
    if (progress && (k % 16 == 0 || k + 1 == n)) progress(k + 1, n);
  }
  return out;
}

}  // namespace skylane::integrity
