#pragma once
/// \file
/// \brief Protection-level prediction over time at one place from almanacs or ephemerides.

#include "integrity/geometry_file.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "integrity/araim/mhss.hpp"
#include "integrity/pl_summary.hpp"
#include "integrity/raim/raim.hpp"
#include "maps/sky_mask.hpp"

#include <functional>
#include <optional>
#include <vector>

namespace skylane::integrity {

/// \brief What to predict.
struct PredictRequest {
  maps::Geodetic place;
  GpsTime start;
  double duration_s = 86400.0;
  double step_s = 600.0;
  double mask_rad = 5.0 * M_PI / 180.0;
  ErrorModel model;
  RaimConfig raim;
  AraimConfig araim;  ///< its requirements are the ones used for availability
  /// The PLs of a user who detects and excludes: the maximum over the exclusion outcomes
  /// (pl_summary.hpp protectionLevels); false: detection only.
  bool with_exclusion = false;
  /// Buildings and terrain around the place (maps::computeSkyMask): a satellite above
  /// mask_rad but not above its azimuth bin's blocked elevation is dropped.
  std::optional<maps::SkyMask> sky_mask;
};



/// \brief Dilutions of precision of an unweighted geometry (∞ when singular).
struct Dops {
  double gdop = 0, pdop = 0, hdop = 0, vdop = 0;
};

/// \brief One predicted epoch.
struct PredictSample {
  GpsTime t;
  std::vector<SatLook> sats;  ///< the satellites used: above the mask and not behind the sky mask
  std::size_t blocked = 0;    ///< satellites above mask_rad dropped by the sky mask
  Dops dops;
  PlSummary pl;
};

/// \brief DOPs of the geometry's G (unit weights).
[[nodiscard]] Dops computeDops(const Geometry& g);

/// \brief One epoch at `req.place` and time t (req.start, duration and step are not used):
/// satellites above the mask and outside the sky mask, DOPs and PLs.
[[nodiscard]] PredictSample predictAt(const OrbitSource& orbits, const PredictRequest& req, const GpsTime& t,
                                      IntegrityMethod method);

/// \brief PLs at every step from start to start + duration (inclusive).
[[nodiscard]] std::vector<PredictSample> predictIntegrity(const OrbitSource& orbits, const PredictRequest& req,
                                                          IntegrityMethod method,
                                                          const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace skylane::integrity
