#pragma once
/// \file
/// \brief Preflight protection levels of a GNSS/INS vehicle along a timed route: the tracker's
/// own filter and integrity flow (integrity::ins::Navigator with trackingNavigatorConfig) run
/// along the route on error-free measurements, so that its PLs are the covariance terms of the
/// formulas the tracker evaluates live (docs/method.md §7.1, "PLs for the vehicle's navigation").
///
/// The run, step by step:
/// 1. the truth along the route: position where(t), velocity by a central difference over one
///    IMU interval, level attitude with the nose along the horizontal velocity (the last heading
///    while hovering or climbing straight up);
/// 2. the filter aligns at the truth at departure (as the tracker aligns at a snapshot, with its
///    position σ, ins::kTrackingAlignPositionSigma_m), with a zero clock;
/// 3. between GNSS epochs, IMU increments at the IMU grade's rate that carry the filter's own
///    state to the truth (ins::bodyIncrements), so the filter follows the route;
/// 4. at each GNSS epoch — every kGnssEpoch_s after departure and at every sample time — the
///    satellites above the mask and outside the sample's sky mask, each with the pseudorange the
///    filter predicts, and the barometer and heading it predicts: every innovation is zero.
///    The filter's covariance (and bias sensitivities) evolve exactly as in flight with this
///    geometry, IMU and aiding; the random parts of the PLs (|A ν|, |K ν|) are zero;
/// 5. at a sample time the epoch's fault-mode PL (the navigator's output, the PL the tracker
///    checks) and the three-hypothesis INS PL beside it.
/// What it does not predict: the innovation-dependent terms in flight (a few tenths of σ on
/// average), faults, and the first fix's snapshot PL before the tracker aligns.

#include "integrity/gnss/orbit_source.hpp"
#include "integrity/ins/navigator.hpp"
#include "maps/geodesy.hpp"
#include "maps/time.hpp"

#include <functional>
#include <vector>

namespace skylane::planner {

/// \brief The GNSS epoch spacing of the prediction [s]: a receiver's 1 Hz fixes, the rate the
/// tracker's filter is updated at in flight (and the rehearsal simulator's GNSS rate).
inline constexpr double kGnssEpoch_s = 1.0;

/// \brief What the GNSS/INS prediction runs along.
struct InsPredictionInput {
  maps::GpsTime departure;
  double duration_s = 0.0;                        ///< the route's flight time
  std::function<maps::Geodetic(double t_s)> where;  ///< the route at t after departure
  std::vector<double> sample_t_s;                 ///< ascending, within [0, duration]
  /// Whether a satellite seen from sample k's place is outside that sample's sky mask (empty:
  /// open sky); epochs between samples use the previous sample's.
  std::function<bool(std::size_t k, const maps::LookAngles& look)> outside_sky_mask;
  integrity::ins::NavigatorConfig config;  ///< the tracker's (trackingNavigatorConfig)
  double imu_rate_hz = 100.0;
};

/// \brief The predicted PLs at one sample.
struct InsPredictedPl {
  bool available = false;  ///< the fault-mode PL exists (enough satellites)
  double hpl_m = 0.0, vpl_m = 0.0;  ///< fault-mode PLs (the tracker's)
  bool three_hypothesis_available = false;
  double three_hypothesis_hpl_m = 0.0, three_hypothesis_vpl_m = 0.0;
  int satellites = 0;  ///< used at the epoch
  int blocked = 0;     ///< above the mask but behind the sky mask
};

/// \brief Runs the file comment's steps; one result per input sample.
/// \throws std::invalid_argument for a non-finite or negative duration, no `where`, sample times
/// not ascending or outside [0, duration], or a non-positive IMU rate.
[[nodiscard]] std::vector<InsPredictedPl> predictInsProtectionLevels(const integrity::OrbitSource& orbits,
                                                                     const InsPredictionInput& input);

}  // namespace skylane::planner
