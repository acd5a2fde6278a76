#pragma once
/// \file
/// \brief Keplerian orbits (almanac and broadcast ephemeris) → satellite position and clock.
///
/// Implements the user algorithm of IS-GPS-200N Table 20-IV (ephemeris) and Table 20-VI /
/// §20.3.3.5.2.2 (almanac), and the identical Galileo OS SIS ICD v2.0 §5.1.1 Table 58, with
/// each system's μ and Ω̇e. Clock: IS-GPS-200N §20.3.3.3.3.1 (af0, af1, af2, relativistic term
/// Δt_r = F·e·√A·sin E_k, group delay T_GD); Galileo ICD §5.1.4 and §5.1.5 (BGD).

#include "integrity/gnss/gnss_time.hpp"
#include "integrity/gnss/satellite_id.hpp"

#include <Eigen/Core>

namespace skylane::integrity {

inline constexpr double kSpeedOfLight_mps = 299792458.0;
/// \brief WGS-84 Earth rotation rate used by GPS and Galileo [rad/s] (IS-GPS-200 Table 20-IV).
inline constexpr double kEarthRotation_radps = 7.2921151467e-5;
/// \brief GPS value of the WGS-84 gravitational constant μ [m³/s²] (IS-GPS-200 Table 20-IV).
inline constexpr double kMuGps = 3.986005e14;
/// \brief Galileo value of μ [m³/s²] (Galileo OS SIS ICD Table 58).
inline constexpr double kMuGalileo = 3.986004418e14;

/// \brief Keplerian elements with harmonic corrections. Almanacs leave the corrections 0.
struct KeplerOrbit {
  Constellation constellation = Constellation::kGps;
  GpsTime toe;            ///< reference time of ephemeris (or almanac t_oa)
  double sqrt_a = 0.0;    ///< √A [√m]
  double e = 0.0;         ///< eccentricity
  double i0_rad = 0.0;    ///< inclination at toe
  double omega0_rad = 0.0;  ///< longitude of ascending node at the weekly epoch
  double omega_rad = 0.0;   ///< argument of perigee
  double m0_rad = 0.0;      ///< mean anomaly at toe
  double delta_n_radps = 0.0;
  double omega_dot_radps = 0.0;
  double idot_radps = 0.0;
  double cuc = 0.0, cus = 0.0;  ///< argument-of-latitude corrections [rad]
  double crc = 0.0, crs = 0.0;  ///< radius corrections [m]
  double cic = 0.0, cis = 0.0;  ///< inclination corrections [rad]
};

/// \brief A satellite's ECEF position (frame of the evaluation instant) and eccentric anomaly.
struct OrbitState {
  Eigen::Vector3d p_ecef = Eigen::Vector3d::Zero();
  double eccentric_anomaly_rad = 0.0;
};

/// \brief Satellite position at GPS time t from Keplerian elements (IS-GPS-200 Table 20-IV).
[[nodiscard]] OrbitState keplerPosition(const KeplerOrbit& orbit, const GpsTime& t);

/// \brief Relativistic clock correction Δt_r = F·e·√A·sin E_k [s], F = −2√μ/c².
[[nodiscard]] double relativisticClock(const KeplerOrbit& orbit, double eccentric_anomaly_rad);

/// \brief One broadcast navigation message record (GPS LNAV or Galileo I/NAV / F/NAV).
struct BroadcastEphemeris {
  SatId sat;
  KeplerOrbit orbit;
  GpsTime toc;          ///< clock reference time
  double af0_s = 0.0, af1_sps = 0.0, af2_sps2 = 0.0;
  double tgd_s = 0.0;   ///< GPS T_GD (L1/L2); Galileo BGD E5a/E1
  double bgd_e5b_s = 0.0;  ///< Galileo BGD E5b/E1 (0 for GPS)
  int iode = 0;         ///< GPS IODE / Galileo IODnav
  int health = 0;       ///< 0 = healthy
  double accuracy_m = 0.0;  ///< GPS URA / Galileo SISA [m]
  double fit_interval_h = 4.0;
  int data_sources = 0;  ///< Galileo: bit 0 I/NAV E1-B, bit 1 F/NAV E5a-I, bit 2 I/NAV E5b-I
  int source_line = 0;  ///< line in the file where the record starts
};

/// \brief Position and clock of one satellite at one instant.
struct SatelliteState {
  SatId sat;
  Eigen::Vector3d p_ecef = Eigen::Vector3d::Zero();  ///< ECEF at the instant given
  double clock_s = 0.0;       ///< clock offset incl. relativistic term, excl. group delay
  double relativistic_s = 0.0;  ///< the relativistic part of clock_s
};

/// \brief Satellite clock polynomial at t (without relativistic term), IS-GPS-200 Eq. 20.3.3.3.3.1.
[[nodiscard]] double clockPolynomial(const BroadcastEphemeris& eph, const GpsTime& t);

/// \brief Position and clock from a broadcast ephemeris at GPS time t (satellite time).
[[nodiscard]] SatelliteState satelliteState(const BroadcastEphemeris& eph, const GpsTime& t);

/// \brief Rotates an ECEF position by the Earth's rotation during the signal flight time
/// (Sagnac correction): the position at transmit time, expressed in the ECEF frame of the
/// reception instant.
[[nodiscard]] Eigen::Vector3d earthRotationCorrection(const Eigen::Vector3d& p_ecef_tx,
                                                      double flight_time_s);

}  // namespace skylane::integrity
