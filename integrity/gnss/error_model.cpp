#include "integrity/gnss/error_model.hpp"

#include "integrity/gnss/atmosphere.hpp"

#include <cmath>

namespace skylane::integrity {
namespace {

constexpr double kFreqL1_hz = 1575.42e6;
constexpr double kFreqL5_hz = 1176.45e6;
constexpr double kDeg = M_PI / 180.0;

}  // namespace

IsmEntry defaultIsm(Constellation c) {
  if (c == Constellation::kGps) return IsmEntry{0.75, 0.5, 0.5, 1e-5, 1e-8};
  return IsmEntry{0.96, 0.64, 0.5, 1e-5, 1e-4};
}

double sigmaTropo_m(double el) {
  const double s = std::sin(el);
  return 0.12 * 1.001 / std::sqrt(0.002001 + s * s);
}

double sigmaMultipath_m(double el) { return 0.13 + 0.53 * std::exp(-el / (10.0 * kDeg)); }

double sigmaNoise_m(double el) { return 0.15 + 0.43 * std::exp(-el / (6.9 * kDeg)); }

double ionoFreeNoiseFactor() {
  const double f1s = kFreqL1_hz * kFreqL1_hz, f5s = kFreqL5_hz * kFreqL5_hz;
  return (f1s * f1s + f5s * f5s) / ((f1s - f5s) * (f1s - f5s));
}

double sigmaIonoSingleFrequency_m(double el, double tau_vert_m) { return ionoObliquityFactor(el) * tau_vert_m; }

double ionoTauVert_m(double geomagnetic_lat_rad) {
  const double lat = std::abs(geomagnetic_lat_rad) / kDeg;
  if (lat <= 20.0) return 9.0;
  if (lat <= 22.5) return 9.0 + (4.5 - 9.0) * (lat - 20.0) / 2.5;
  if (lat <= 55.0) return 4.5;
  return 6.0;
}

double sigmaUserSquared(UserErrorModel model, double el, double tau_vert_m) {
  const double mp = sigmaMultipath_m(el), n = sigmaNoise_m(el);
  if (model == UserErrorModel::kDualFrequency) return ionoFreeNoiseFactor() * (mp * mp + n * n);  // ADD Eq. 3
  const double iono = sigmaIonoSingleFrequency_m(el, tau_vert_m);
  return mp * mp + n * n + iono * iono;
}

RangeSigma rangeSigma(const ErrorModel& model, Constellation c, double el, double tau_vert_m) {
  const IsmEntry& ism = model.of(c);
  const double tropo = sigmaTropo_m(el);
  const double user2 = sigmaUserSquared(model.user_model[static_cast<int>(c)], el, tau_vert_m);
  RangeSigma r;
  r.sigma_int_m = std::sqrt(ism.ura_m * ism.ura_m + tropo * tropo + user2);  // ADD Eq. 1
  r.sigma_acc_m = std::sqrt(ism.ure_m * ism.ure_m + tropo * tropo + user2);  // ADD Eq. 2
  r.bnom_m = ism.bnom_m;
  return r;
}

}  // namespace skylane::integrity
