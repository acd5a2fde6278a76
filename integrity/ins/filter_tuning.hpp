#pragma once
/// \file
/// \brief The GNSS/INS filter tuned to the sensors it is fed (docs/method.md §5.1): the IMU's
/// noise and bias figures, the receiver clock, barometer and magnetometer — the same figures the
/// simulator draws its errors from, so the filter's covariance describes the errors it sees.

#include "integrity/gnss/error_model.hpp"
#include "integrity/ins/imu_grade.hpp"
#include "integrity/ins/navigator.hpp"

#include <cmath>

namespace skylane::integrity::ins {

/// \brief The error figures of the sensors around the IMU (1σ).
struct SensorErrorSpec {
  ImuSpec imu = imuSpec(ImuGrade::kConsumer);
  double clock_h0 = 2e-19;    ///< receiver oscillator Allan coefficients (TCXO)
  double clock_hm2 = 2e-20;
  double baro_noise_m = 0.3;       ///< white noise σ of each barometric height
  double baro_bias_m = 3.0;        ///< turn-on bias σ
  double baro_bias_rw_m_rts = 0.01;
  double heading_noise_rad = 2.0 * M_PI / 180.0;  ///< magnetometer heading σ (declination known)
};

/// \brief Sets the filter's process and measurement noise from `sensors`, and the
/// three-hypothesis INS PL's error weight ratio and risk split from `grade` and the fault-mode
/// risk allocation (the filter's other settings stay as they are).
void tuneFilterToSensors(NavigatorConfig& nav, const SensorErrorSpec& sensors, ImuGrade grade);

/// \brief The filter's initial position σ per axis when a tracker aligns it at a snapshot fix
/// (a snapshot's error is a few metres) [m]; the preflight prediction aligns with it too.
inline constexpr double kTrackingAlignPositionSigma_m = 10.0;

/// \brief The navigator a live tracker runs for an IMU of `grade` (the grade's datasheet figures,
/// the default clock, barometer and magnetometer), with the mission's error model and mask,
/// `initial_position_m` the σ of the snapshot it aligns at, and no snapshot ARAIM beside it.
[[nodiscard]] NavigatorConfig trackingNavigatorConfig(ImuGrade grade, const ErrorModel& model, double elevation_mask_rad,
                                                      double initial_position_m);

}  // namespace skylane::integrity::ins
