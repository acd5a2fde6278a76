#include "integrity/availability.hpp"

#include "integrity/gnss/atmosphere.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace skylane::integrity {

double AvailabilityMap::coveragePercent(double min_pct) const {
  double total = 0, covered = 0;
  for (const AvailabilityCell& c : cells) {
    const double w = std::cos(maps::deg2rad(c.lat_deg));  // cell area ∝ cos(latitude)
    total += w;
    if (c.percent() >= min_pct) covered += w;
  }
  return total > 0 ? 100.0 * covered / total : 0.0;
}

AvailabilityMap computeAvailability(const OrbitSource& orbits, const AvailabilityRequest& req,
                                    const std::function<void(std::size_t, std::size_t)>& progress) {
  if (!(req.grid_deg > 0 && req.grid_deg <= 90) || !(req.step_s > 0) || !(req.duration_s >= 0)) {
    throw std::invalid_argument("availability: grid in (0, 90] degrees, positive step and duration required");
  }
  AvailabilityMap map;
  map.rows = static_cast<int>(std::round(180.0 / req.grid_deg));
  map.cols = static_cast<int>(std::round(360.0 / req.grid_deg));
  map.cells.resize(static_cast<std::size_t>(map.rows * map.cols));
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      AvailabilityCell& cell = map.cells[static_cast<std::size_t>(r * map.cols + c)];
      cell.lat_deg = -90.0 + req.grid_deg * (r + 0.5);
      cell.lon_deg = -180.0 + req.grid_deg * (c + 0.5);
    }
  }
  // Epochs in [start, start + duration): a 24 h run at 10 min has 144, as in MAAST.
  const auto n_epochs = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(req.duration_s / req.step_s - 1e-9)));
  // Satellite positions depend on time only: compute them once per epoch for all users.
  std::vector<std::vector<std::pair<SatId, Eigen::Vector3d>>> sky(n_epochs);
  for (std::size_t k = 0; k < n_epochs; ++k) sky[k] = orbits.positionsForAllUsers(req.start.plus(k * req.step_s));

  const std::size_t total = map.cells.size() * n_epochs;
  map.user_epochs = total;
  std::atomic<std::size_t> next_cell{0}, done{0};
  std::mutex progress_mutex;
  auto worker = [&]() {
    for (std::size_t i = next_cell++; i < map.cells.size(); i = next_cell++) {
      AvailabilityCell& cell = map.cells[i];
      const maps::Geodetic user{maps::deg2rad(cell.lat_deg), maps::deg2rad(cell.lon_deg), req.user_h_m};
      const Eigen::Vector3d p_user = maps::geodeticToEcef(user);
      const Eigen::Matrix3d R = maps::rotationEcefToEnu(user.lat_rad, user.lon_rad);
      const double tau = req.model.iono_tau_vert_m.value_or(ionoTauVert_m(geomagneticLatitude(user)));
      std::vector<SatLook> looks;
      for (std::size_t k = 0; k < n_epochs; ++k) {
        looks.clear();
        for (const auto& [sat, p] : sky[k]) {
          const Eigen::Vector3d d = R * (p - p_user);
          const double el = std::atan2(d.z(), std::hypot(d.x(), d.y()));
          if (el < req.mask_rad) continue;
          double az = std::atan2(d.x(), d.y());
          if (az < 0) az += 2 * M_PI;
          looks.push_back({sat, {az, el}});
        }
        const Geometry g = buildGeometry(looks, req.model, tau);
        const PlSummary s = protectionLevels(g, req.method, req.model, req.raim, req.araim, req.with_exclusion);
        ++cell.epochs;
        cell.available += s.available ? 1 : 0;
        if (s.pl_computed) {
          cell.max_vpl_m = std::max(cell.max_vpl_m, s.vpl_m);
          cell.max_hpl_m = std::max(cell.max_hpl_m, s.hpl_m);
        }
      }
      const std::size_t d = done += n_epochs;
      if (progress) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        progress(d, total);
      }
    }
  };
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const unsigned n_threads = req.threads > 0 ? static_cast<unsigned>(req.threads) : hw;
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < n_threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  return map;
}

}  // namespace skylane::integrity
