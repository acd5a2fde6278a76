#pragma once
/// \file
/// \brief Worldwide integrity availability: the percentage of epochs at which the protection
/// levels meet the requirements, on a latitude/longitude grid (the map Stanford's MAAST draws).

#include "integrity/gnss/orbit_source.hpp"
#include "integrity/pl_summary.hpp"

#include <functional>
#include <vector>

namespace skylane::integrity {

/// \brief What to compute.
struct AvailabilityRequest {
  double grid_deg = 5.0;  ///< cell size; points at cell centres (−90 + g/2 … 90 − g/2, −180 + g/2 …)
  GpsTime start;
  double duration_s = 86400.0;  ///< epochs start, start + step, … < start + duration
  double step_s = 600.0;
  double mask_rad = 5.0 * M_PI / 180.0;
  double user_h_m = 0.0;  ///< ellipsoidal height of every user
  IntegrityMethod method = IntegrityMethod::kAraim;
  ErrorModel model;
  RaimConfig raim;
  AraimConfig araim;
  bool with_exclusion = false;  ///< the PLs of a user who excludes (PredictRequest::with_exclusion)
  int threads = 0;  ///< 0 = all hardware threads
};

/// \brief One grid point's statistics.
struct AvailabilityCell {
  double lat_deg = 0, lon_deg = 0;
  int epochs = 0;
  int available = 0;
  double max_vpl_m = 0, max_hpl_m = 0;  ///< over epochs where the PL was computed
  [[nodiscard]] double percent() const { return epochs ? 100.0 * available / epochs : 0.0; }
};

/// \brief The map: rows by latitude (south to north), columns by longitude (west to east).
struct AvailabilityMap {
  int rows = 0, cols = 0;
  std::vector<AvailabilityCell> cells;  ///< row-major
  std::size_t user_epochs = 0;
  [[nodiscard]] double coveragePercent(double min_availability_pct) const;  ///< area-weighted
};

/// \brief Computes the map on `threads` threads; `progress(done, total)` counts user-epochs
/// and is called from one thread at a time.
[[nodiscard]] AvailabilityMap computeAvailability(const OrbitSource& orbits, const AvailabilityRequest& req,
                                                  const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace skylane::integrity
