#pragma once
/// \file
/// \brief Sensor simulation for the GNSS/INS proof: IMU increments per grade, GNSS pseudoranges
/// from real orbits with the error model of docs/method.md §2, barometric height, magnetometer heading,
/// and fault injection. Every random draw comes from one seeded generator.
///
/// IMU grades and their figures: integrity/ins/imu_grade.hpp.
///
/// Pseudorange (per satellite i, epoch k): ρ = |r_s − r| (light time and Sagnac, as
/// OrbitSource::visible) + c·δt_r + b_i + ε_i,k + f_i,k, with
/// - c·δt_r: receiver clock bias and drift, random walks (TCXO, h₀ = 2e-19, h₋₂ = 2e-20: q_b =
///   c²h₀/2, q_d = 2π²c²h₋₂, Brown & Hwang 4th ed. §9.3);
/// - b_i: the nominal bias of the ARAIM ISM, constant over a pass, uniform in [−b_nom, b_nom];
/// - ε_i,k ~ N(0, σ²_acc,i): σ²_URE + σ²_tropo(θ) + σ²_user(θ) (clock/orbit, troposphere, noise
///   and multipath), white at the GNSS rate — the filter assumes σ_int ≥ σ_acc and |b| ≤ b_nom;
/// - f_i,k: injected faults.

#include "integrity/gnss/error_model.hpp"
#include "integrity/gnss/gnss_time.hpp"
#include "integrity/gnss/orbit_source.hpp"
#include "integrity/gnss/satellite_id.hpp"
#include "integrity/ins/filter_tuning.hpp"
#include "integrity/ins/imu_grade.hpp"
#include "integrity/ins/strapdown.hpp"
#include "integrity/sim/trajectory.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::integrity::sim {

using ins::ImuGrade;
using ins::imuGradeName;
using ins::ImuSpec;
using ins::imuSpec;
using ins::parseImuGrade;

/// \brief What a fault acts on.
enum class FaultTarget { kSatellite, kAccelerometer, kGyro, kGnssOutage };

/// \brief One injected fault over [t_start, t_end).
struct FaultSpec {
  FaultTarget target = FaultTarget::kSatellite;
  std::vector<SatId> sats;   ///< kSatellite: the satellites biased
  int axis = 2;              ///< accelerometer / gyro: body axis 0 = forward, 1 = left, 2 = up
  double t_start_s = 0.0;
  double t_end_s = 0.0;
  bool ramp = false;         ///< false: step of `magnitude`; true: grows by `magnitude` per second
  double magnitude = 0.0;    ///< m (satellite), m/s² (accelerometer), rad/s (gyro)
  bool in_sigma = false;     ///< satellite: magnitude in units of the satellite's σ_int (Zhao & Song's σ₀)
  /// \brief Satellite fault with no `sats`: when the fault starts, the satellite at position
  /// ⌊pick·n⌋ of the n in view (in id order) is chosen and kept.
  double pick = -1.0;
  /// \brief The fault's value at t (0 outside the window).
  [[nodiscard]] double valueAt(double t_s) const;
};

/// \brief Sensor settings: the IMU, clock, barometer and magnetometer figures the filter is
/// tuned to (ins::SensorErrorSpec), and the GNSS side.
struct SensorSpec : ins::SensorErrorSpec {
  double gnss_rate_hz = 1.0;
  double elevation_mask_rad = 5.0 * M_PI / 180.0;
  ErrorModel model;
};

/// \brief One IMU interval's increments (what the IMU outputs).
struct ImuSample {
  double t_s = 0.0;  ///< end of the interval
  double dt_s = 0.0;
  Eigen::Vector3d dtheta_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv_mps = Eigen::Vector3d::Zero();
};

/// \brief One pseudorange with what the receiver knows about it.
struct Pseudorange {
  SatId sat;
  Eigen::Vector3d sat_ecef_m = Eigen::Vector3d::Zero();  ///< at transmit time, in the reception frame
  double pseudorange_m = 0.0;
  double elevation_rad = 0.0;
  double azimuth_rad = 0.0;
  double injected_m = 0.0;  ///< the injected fault (truth, for the record)
};

/// \brief One GNSS epoch.
struct GnssEpoch {
  double t_s = 0.0;
  GpsTime time;
  bool outage = false;
  std::vector<Pseudorange> ranges;
};

/// \brief Aiding samples at the GNSS epochs.
struct AidingSample {
  double baro_h_m = 0.0;       ///< ellipsoidal height + baro bias + noise
  double heading_rad = 0.0;    ///< true heading + noise
};

/// \brief Steps the truth and the sensors together.
class SensorSimulator {
 public:
  /// \brief `start` is the GPS time at t = 0 of the trajectory.
  SensorSimulator(const Trajectory& trajectory, const OrbitSource& orbits, const GpsTime& start, SensorSpec spec,
                  std::vector<FaultSpec> faults, std::uint64_t seed);

  /// \brief Truth at the current time.
  [[nodiscard]] const TruthState& truth() const { return truth_; }
  /// \brief Truth as a navigation state (ECEF).
  [[nodiscard]] const ins::NavState& truthNav() const { return truth_nav_; }
  /// \brief The current time [s].
  [[nodiscard]] double time_s() const { return truth_.t_s; }
  /// \brief True while the trajectory has not ended.
  [[nodiscard]] bool running() const { return truth_.t_s + 0.5 / spec_.imu.rate_hz < trajectory_.duration_s(); }
  /// \brief Advances one IMU interval and returns the measured increments.
  ImuSample stepImu();
  /// \brief True when the current time is a GNSS epoch.
  [[nodiscard]] bool gnssDue() const;
  /// \brief The GNSS measurements at the current time.
  [[nodiscard]] GnssEpoch gnss();
  /// \brief Barometer and magnetometer at the current time.
  [[nodiscard]] AidingSample aiding();
  /// \brief True IMU biases now (accelerometer, gyro) including injected faults.
  [[nodiscard]] Eigen::Vector3d accelBias() const { return accel_bias_; }
  [[nodiscard]] Eigen::Vector3d gyroBias() const { return gyro_bias_; }
  /// \brief True receiver clock bias [m].
  [[nodiscard]] double clockBias_m() const { return clock_m_; }
  [[nodiscard]] const GpsTime& startTime() const { return start_; }
  [[nodiscard]] const SensorSpec& spec() const { return spec_; }

 private:
  double normal() { return gauss_(rng_); }

  const Trajectory& trajectory_;
  const OrbitSource& orbits_;
  GpsTime start_;
  SensorSpec spec_;
  std::vector<FaultSpec> faults_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> gauss_{0.0, 1.0};
  long step_ = 0;
  int imu_per_gnss_ = 100;
  TruthState truth_;
  ins::NavState truth_nav_;
  Eigen::Vector3d accel_bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
  double clock_m_ = 0.0;
  double clock_drift_mps_ = 0.0;
  double baro_bias_m_ = 0.0;
  std::map<SatId, double> nominal_bias_m_;
};

}  // namespace skylane::integrity::sim
