#pragma once
/// \file
/// \brief Atmospheric delay corrections for single-point positioning.

#include "integrity/gnss/gnss_time.hpp"
#include "integrity/gnss/rinex_nav.hpp"

#include "maps/geodesy.hpp"

namespace skylane::integrity {

/// \brief GPS L1 ionospheric delay [m] from the broadcast Klobuchar model,
/// IS-GPS-200N §20.3.3.5.2.5 and Figure 20-4 (semicircle arithmetic as in the ICD).
[[nodiscard]] double klobucharDelay_m(const KlobucharParams& k, const maps::Geodetic& user,
                                      const maps::LookAngles& look, const GpsTime& t);

/// \brief Tropospheric slant delay [m] from the Saastamoinen model (J. Saastamoinen, "Atmospheric
/// correction for the troposphere and stratosphere in radio ranging of satellites", AGU
/// Geophys. Monogr. 15, 1972) with a standard atmosphere (1013.25 hPa, 15 °C at sea level,
/// 70 % relative humidity, lapse per Berg 1948), zenith delay mapped by 1/cos z.
[[nodiscard]] double saastamoinenDelay_m(const maps::Geodetic& user, double elevation_rad);

/// \brief Ionospheric pierce-point obliquity factor F_pp (RTCA DO-229E Eq. A-42, shell 350 km).
[[nodiscard]] double ionoObliquityFactor(double elevation_rad);

/// \brief Geomagnetic latitude [rad] of the pierce point region (dipole at 78.3° N, 291.0° E, as
/// in DO-229E A.4.4.10.3), used to choose τ_vert of the single-frequency error model.
[[nodiscard]] double geomagneticLatitude(const maps::Geodetic& user);

}  // namespace skylane::integrity
