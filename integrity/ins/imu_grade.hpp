#pragma once
/// \file
/// \brief IMU grades and their error figures (docs/method.md §5.1). The turn-on biases are the
/// grade table of the GNSS/INS integrity patent (accelerometer / gyro bias per grade); the noise
/// and bias random walks are not in it and are skylane's documented choices, typical datasheet
/// values:
/// | grade    | accel bias σ | gyro bias σ      | VRW (m/s/√s) | ARW (rad/√s) | accel / gyro bias RW        |
/// | aviation | 3e-4 m/s²    | 5e-8 rad/s       | 2e-4         | 5.8e-7       | 1e-6 m/s²/√s / 1e-9 rad/s/√s |
/// | tactical | 1e-2 m/s²    | 5e-6 rad/s       | 8.3e-4       | 2.9e-5       | 1e-4 / 1e-7                  |
/// | consumer | 3e-2 m/s²    | 5e-4 rad/s (¹)   | 2.0e-3       | 1.75e-4      | 3e-4 / 1e-5                  |
/// (¹) The patent's consumer gyro exponent is unreadable ("> 5 × 10^?"); 5e-4 rad/s (≈ 100 °/h)
/// is the tactical upper bound and typical of MEMS gyros.

#include <optional>
#include <string_view>

namespace skylane::integrity::ins {

/// \brief The three IMU grades.
enum class ImuGrade { kAviation, kTactical, kConsumer };

/// \brief "aviation", "tactical", "consumer".
[[nodiscard]] std::string_view imuGradeName(ImuGrade g);
/// \brief Parses a grade name; std::nullopt when unknown.
[[nodiscard]] std::optional<ImuGrade> parseImuGrade(std::string_view name);

/// \brief IMU error figures (1σ; noise as random-walk coefficients).
struct ImuSpec {
  double accel_bias_mps2 = 0.0;       ///< turn-on bias σ per axis
  double gyro_bias_radps = 0.0;
  double accel_noise_mps_rts = 0.0;   ///< velocity random walk [m/s/√s]
  double gyro_noise_rad_rts = 0.0;    ///< angle random walk [rad/√s]
  double accel_bias_rw_mps2_rts = 0.0;  ///< bias random walk [m/s²/√s]
  double gyro_bias_rw_radps_rts = 0.0;  ///< [rad/s/√s]
  double rate_hz = 100.0;
};

/// \brief The figures of the file comment's table.
[[nodiscard]] ImuSpec imuSpec(ImuGrade g);

}  // namespace skylane::integrity::ins
