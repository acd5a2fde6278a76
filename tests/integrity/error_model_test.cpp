#include "integrity/gnss/error_model.hpp"

#include "integrity/gnss/atmosphere.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace skylane::integrity {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(ErrorModel, IonoFreeFactorIsTheAddValue) {
  EXPECT_NEAR(ionoFreeNoiseFactor(), 6.6995, 5e-5);  // (f1⁴+f5⁴)/(f1²−f5²)², ARAIM ADD
}

TEST(ErrorModel, TropoMultipathAndNoiseFollowTheirFormulas) {
  EXPECT_NEAR(sigmaTropo_m(90 * kDeg), 0.12 * 1.001 / std::sqrt(1.002001), 1e-12);
  EXPECT_NEAR(sigmaTropo_m(5 * kDeg), 0.12 * 1.001 / std::sqrt(0.002001 + std::pow(std::sin(5 * kDeg), 2)), 1e-12);
  EXPECT_NEAR(sigmaMultipath_m(10 * kDeg), 0.13 + 0.53 / M_E, 1e-12);
  EXPECT_NEAR(sigmaNoise_m(6.9 * kDeg), 0.15 + 0.43 / M_E, 1e-12);
}

TEST(ErrorModel, DualFrequencySigmaAtZenithAndAtFiveDegrees) {
  // Independent evaluation of ADD Eq. 1 for GPS (σ_URA 0.75 m) at 90° and 5° elevation.
  const ErrorModel m;
  for (double el_deg : {90.0, 5.0}) {
    const double el = el_deg * kDeg;
    const double mp = 0.13 + 0.53 * std::exp(-el_deg / 10.0), n = 0.15 + 0.43 * std::exp(-el_deg / 6.9);
    const double tr = 0.12 * 1.001 / std::sqrt(0.002001 + std::sin(el) * std::sin(el));
    const double expect = std::sqrt(0.75 * 0.75 + tr * tr + 6.6995 * (mp * mp + n * n));
    EXPECT_NEAR(rangeSigma(m, Constellation::kGps, el, 9.0).sigma_int_m, expect, 1e-4) << el_deg;
  }
  EXPECT_NEAR(rangeSigma(m, Constellation::kGps, 90 * kDeg, 9.0).bnom_m, 0.5, 1e-12);
}

TEST(ErrorModel, SigmaGrowsAsElevationFalls) {
  ErrorModel m;
  for (UserErrorModel u : {UserErrorModel::kDualFrequency, UserErrorModel::kSingleFrequency}) {
    m.setUserModel(u);
    double prev = 0.0;
    for (double el = 90; el >= 2; el -= 1) {
      const double s = rangeSigma(m, Constellation::kGalileo, el * kDeg, 4.5).sigma_int_m;
      EXPECT_GE(s, prev) << el;
      prev = s;
    }
  }
}

TEST(ErrorModel, SingleFrequencyIonoUsesObliquityAndTauVert) {
  EXPECT_NEAR(ionoObliquityFactor(M_PI / 2), 1.0, 1e-12);
  // DO-229E A-42 at 5°: [1 − (6378.1363·cos 5° / 6728.1363)²]^(−1/2) = 3.041.
  EXPECT_NEAR(ionoObliquityFactor(5 * kDeg), 3.041, 0.001);
  EXPECT_DOUBLE_EQ(ionoTauVert_m(10 * kDeg), 9.0);
  EXPECT_DOUBLE_EQ(ionoTauVert_m(40 * kDeg), 4.5);
  EXPECT_DOUBLE_EQ(ionoTauVert_m(-70 * kDeg), 6.0);
  EXPECT_NEAR(sigmaIonoSingleFrequency_m(M_PI / 2, 4.5), 4.5, 1e-12);
}

TEST(ErrorModel, KlobucharDelayAtNightIsTheFiveNanosecondFloor) {
  // IS-GPS-200: outside the daytime cosine the vertical delay is 5 ns; at zenith F = 1+16(0.53−0.5)³.
  KlobucharParams k;
  k.alpha = {1.1180e-08, 1.4900e-08, -5.9600e-08, -5.9600e-08};
  k.beta = {8.8060e+04, 1.6380e+04, -1.9660e+05, -1.3110e+05};
  const maps::Geodetic user{35.13 * kDeg, 139.62 * kDeg, 80.0};
  // Local time ≈ UT + 9.3 h: choose UT 15:00 → local ≈ 00:18, night.
  const double d = klobucharDelay_m(k, user, {0.0, M_PI / 2}, GpsTime{1316, 6 * 86400 + 15 * 3600.0});
  EXPECT_NEAR(d, 299792458.0 * 5e-9 * (1 + 16 * std::pow(0.03, 3)), 1e-6);
  // Daytime (local 14:00 ≈ UT 04:40) is larger.
  EXPECT_GT(klobucharDelay_m(k, user, {0.0, M_PI / 2}, GpsTime{1316, 6 * 86400 + 4.7 * 3600.0}), 2.0);
}

TEST(ErrorModel, SaastamoinenZenithDelayIsAboutTwoPointFourMetresAtSeaLevel) {
  const double z = saastamoinenDelay_m({35 * kDeg, 0, 0.0}, M_PI / 2);
  EXPECT_NEAR(z, 2.4, 0.1);
  EXPECT_NEAR(saastamoinenDelay_m({35 * kDeg, 0, 0.0}, 30 * kDeg), z * 2.0, 0.01);  // 1/cos z
}

}  // namespace
}  // namespace skylane::integrity
