#include "integrity/gnss/atmosphere.hpp"

#include <algorithm>
#include <cmath>

namespace skylane::integrity {
namespace {

/// Earth radius and ionospheric shell height of DO-229E A.4.4.10.4 [m].
constexpr double kIonoEarthRadius_m = 6378136.3;
constexpr double kIonoShellHeight_m = 350000.0;
/// Below this elevation the troposphere model is clamped (mapping 1/cos z diverges).
constexpr double kMinTropoElevation_rad = 0.0349;  // 2°

}  // namespace

double klobucharDelay_m(const KlobucharParams& k, const maps::Geodetic& user, const maps::LookAngles& look,
                        const GpsTime& t) {
  // All angles in semicircles as in IS-GPS-200 Figure 20-4.
  const double e = look.elevation_rad / M_PI;
  const double a = look.azimuth_rad;
  const double phi_u = user.lat_rad / M_PI;
  const double lam_u = user.lon_rad / M_PI;
  const double psi = 0.0137 / (e + 0.11) - 0.022;  // Earth-centred angle
  double phi_i = phi_u + psi * std::cos(a);        // sub-ionospheric latitude
  phi_i = std::clamp(phi_i, -0.416, 0.416);
  const double lam_i = lam_u + psi * std::sin(a) / std::cos(phi_i * M_PI);
  const double phi_m = phi_i + 0.064 * std::cos((lam_i - 1.617) * M_PI);  // geomagnetic latitude
  double t_local = std::fmod(4.32e4 * lam_i + t.sow, kSecondsPerDay);
  if (t_local < 0) t_local += kSecondsPerDay;
  const double f = 1.0 + 16.0 * std::pow(0.53 - e, 3);  // obliquity factor
  const double amp = std::max(0.0, k.alpha[0] + phi_m * (k.alpha[1] + phi_m * (k.alpha[2] + phi_m * k.alpha[3])));
  const double per = std::max(72000.0, k.beta[0] + phi_m * (k.beta[1] + phi_m * (k.beta[2] + phi_m * k.beta[3])));
  const double x = 2.0 * M_PI * (t_local - 50400.0) / per;  // phase [rad]
  double delay_s = 5e-9;
  if (std::abs(x) < 1.57) delay_s += amp * (1.0 - x * x / 2.0 + x * x * x * x / 24.0);
  return kSpeedOfLight_mps * f * delay_s;
}

double saastamoinenDelay_m(const maps::Geodetic& user, double elevation_rad) {
  const double h = std::clamp(user.h_ell_m, 0.0, 10000.0);  // the standard atmosphere's range
  const double el = std::max(elevation_rad, kMinTropoElevation_rad);
  const double pressure_hpa = 1013.25 * std::pow(1.0 - 2.2557e-5 * h, 5.2568);
  const double temp_k = 15.0 - 6.5e-3 * h + 273.16;
  const double humidity = 0.7;
  const double e_hpa = 6.108 * humidity * std::exp((17.15 * temp_k - 4684.0) / (temp_k - 38.45));
  const double cos_z = std::cos(M_PI / 2 - el);
  const double dry = 0.0022768 * pressure_hpa /
                     (1.0 - 0.00266 * std::cos(2.0 * user.lat_rad) - 0.00028 * h / 1e3) / cos_z;
  const double wet = 0.002277 * (1255.0 / temp_k + 0.05) * e_hpa / cos_z;
  return dry + wet;
}

double ionoObliquityFactor(double elevation_rad) {
  const double r = kIonoEarthRadius_m * std::cos(elevation_rad) / (kIonoEarthRadius_m + kIonoShellHeight_m);
  return 1.0 / std::sqrt(1.0 - r * r);
}

double geomagneticLatitude(const maps::Geodetic& user) {
  // Klobuchar's dipole approximation (IS-GPS-200 Figure 20-4), in semicircles then radians.
  const double phi = user.lat_rad / M_PI;
  const double lam = user.lon_rad / M_PI;
  return (phi + 0.064 * std::cos((lam - 1.617) * M_PI)) * M_PI;
}

}  // namespace skylane::integrity
