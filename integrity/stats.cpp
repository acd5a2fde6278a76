#include "integrity/stats.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/non_central_chi_squared.hpp>
#include <boost/math/special_functions/erf.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace skylane::integrity {
namespace {

/// Non-centrality bisection stops when the bracket is this narrow (relative), far below the
/// 1e-4 precision of Brown's published tables.
constexpr double kLambdaRelTol = 1e-12;

void requireProbability(double p, const char* what) {
  if (!(p > 0.0 && p < 1.0)) {
    std::ostringstream m;
    m << what << ": probability " << p << " is outside (0, 1)";
    throw std::invalid_argument(m.str());
  }
}

void requireDof(int dof) {
  if (dof < 1) throw std::invalid_argument("chi-square needs at least 1 degree of freedom, got " + std::to_string(dof));
}

}  // namespace

double normalTail(double x) { return 0.5 * std::erfc(x / std::sqrt(2.0)); }

namespace {

/// Horner evaluation of c[0] + c[1] r + … + c[N−1] r^(N−1).
template <std::size_t N>
double horner(const double (&c)[N], double r) {
  double v = c[N - 1];
  for (std::size_t i = N - 1; i-- > 0;) v = v * r + c[i];
  return v;
}

/// Cody (1969) on x = z/√2 ≥ 0: erf(x)/x for x ≤ 0.46875, else e^{x²}erfc(x) — coefficients
/// of his three near-minimax rational approximations, lowest degree first.
double codyErfOverX(double x2) {
  static constexpr double a[5] = {3.20937758913846947e3, 3.77485237685302021e2, 1.13864154151050156e2,
                                  3.16112374387056560e0, 1.85777706184603153e-1};
  static constexpr double b[5] = {2.84423683343917062e3, 1.28261652607737228e3, 2.44024637934444173e2,
                                  2.36012909523441209e1, 1.0};
  return horner(a, x2) / horner(b, x2);
}

double codyScaledErfc(double x) {
  static constexpr double c[9] = {1.23033935479799725e3, 2.05107837782607147e3, 1.71204761263407058e3,
                                  8.81952221241769090e2, 2.98635138197400131e2, 6.61191906371416295e1,
                                  8.88314979438837594e0, 5.64188496988670089e-1, 2.15311535474403846e-8};
  static constexpr double d[9] = {1.23033935480374942e3, 3.43936767414372164e3, 4.36261909014324716e3,
                                  3.29079923573345963e3, 1.62138957456669019e3, 5.37181101862009858e2,
                                  1.17693950891312499e2, 1.57449261107098347e1, 1.0};
  static constexpr double p[6] = {6.58749161529837803e-4, 1.60837851487422766e-2, 1.25781726111229246e-1,
                                  3.60344899949804439e-1, 3.05326634961232344e-1, 1.63153871373020978e-2};
  static constexpr double q[6] = {2.33520497626869185e-3, 6.05183413124413191e-2, 5.27905102951428412e-1,
                                  1.87295284992346047e0,  2.56852019228982242e0,  1.0};
  constexpr double kInvSqrtPi = 0.56418958354775628695;
  if (x <= 4.0) return horner(c, x) / horner(d, x);
  const double y = 1.0 / (x * x);
  return (kInvSqrtPi - y * horner(p, y) / horner(q, y)) / x;
}

}  // namespace

TailAndDensity normalTailAndDensity(double z) {
  constexpr double kInvSqrt2Pi = 0.39894228040143267794, kHalfSqrt2Pi = 1.25331413731550025121;
  constexpr double kInvSqrt2 = 0.70710678118654752440;
  const double zz = z * z, zz_err = std::fma(z, z, -zz);  // z² = zz + zz_err exactly
  const double e = std::exp(-0.5 * zz) * (1.0 - 0.5 * zz_err);
  const double x = z * kInvSqrt2;
  TailAndDensity out;
  out.density = kInvSqrt2Pi * e;
  out.tail = x <= 0.46875 ? 0.5 - 0.5 * x * codyErfOverX(x * x) : kHalfSqrt2Pi * out.density * codyScaledErfc(x);
  return out;
}

namespace {

/// Horner evaluation of c[0] + c[1] r + … + c[7] r⁷.
double poly7(const double (&c)[8], double r) {
  double v = c[7];
  for (int i = 6; i >= 0; --i) v = v * r + c[i];
  return v;
}

/// Φ⁻¹(p) by M. J. Wichura, "Algorithm AS 241: The Percentage Points of the Normal
/// Distribution", Applied Statistics 37(3) 477–484, 1988 (PPND16: rational approximations of
/// degree 7 in three regions, relative accuracy about 1e-16). In the tails it works from
/// r = √(−ln p) of the tail probability itself, so Q⁻¹ of p down to 1e-300 keeps full
/// relative precision.
double normalQuantileAs241(double p) {
  static constexpr double a[8] = {3.3871328727963666080e0,  1.3314166789178437745e+2, 1.9715909503065514427e+3,
                                  1.3731693765509461125e+4, 4.5921953931549871457e+4, 6.7265770927008700853e+4,
                                  3.3430575583588128105e+4, 2.5090809287301226727e+3};
  static constexpr double b[8] = {1.0,
                                  4.2313330701600911252e+1, 6.8718700749205790830e+2, 5.3941960214247511077e+3,
                                  2.1213794301586595867e+4, 3.9307895800092710610e+4, 2.8729085735721942674e+4,
                                  5.2264952788528545610e+3};
  static constexpr double c[8] = {1.42343711074968357734e0,  4.63033784615654529590e0,  5.76949722146069140550e0,
                                  3.64784832476320460504e0,  1.27045825245236838258e0,  2.41780725177450611770e-1,
                                  2.27238449892691845833e-2, 7.74545014278341407640e-4};
  static constexpr double d[8] = {1.0,
                                  2.05319162663775882187e0,  1.67638483018380384940e0,  6.89767334985100004550e-1,
                                  1.48103976427480074590e-1, 1.51986665636164571966e-2, 5.47593808499534494600e-4,
                                  1.05075007164441684324e-9};
  static constexpr double e[8] = {6.65790464350110377720e0,  5.46378491116411436990e0,  1.78482653991729133580e0,
                                  2.96560571828504891230e-1, 2.65321895265761230930e-2, 1.24266094738807843860e-3,
                                  2.71155556874348757815e-5, 2.01033439929228813265e-7};
  static constexpr double f[8] = {1.0,
                                  5.99832206555887937690e-1, 1.36929880922735805310e-1, 1.48753612908506148525e-2,
                                  7.86869131145613259100e-4, 1.84631831751005468180e-5, 1.42151175831644588870e-7,
                                  2.04426310338993978564e-15};
  constexpr double kSplitCentral = 0.425, kSplitTail = 5.0, kCentral = 0.180625, kTailShift = 1.6;
  const double q = p - 0.5;
  if (std::abs(q) <= kSplitCentral) {
    const double r = kCentral - q * q;
    return q * poly7(a, r) / poly7(b, r);
  }
  double r = std::sqrt(-std::log(q < 0.0 ? p : 1.0 - p));
  const double x = r <= kSplitTail ? (r -= kTailShift, poly7(c, r) / poly7(d, r))
                                   : (r -= kSplitTail, poly7(e, r) / poly7(f, r));
  return q < 0.0 ? -x : x;
}

}  // namespace

double normalTailInverse(double p) {
  requireProbability(p, "normalTailInverse");
  return -normalQuantileAs241(p);  // Q⁻¹(p) = −Φ⁻¹(p); exact negation, and p itself feeds the tail branch
}

double normalTailInverseReference(double p) {
  requireProbability(p, "normalTailInverseReference");
  return std::sqrt(2.0) * boost::math::erfc_inv(2.0 * p);
}

double chiSquareUpperQuantile(int dof, double p) {
  requireDof(dof);
  requireProbability(p, "chiSquareUpperQuantile");
  const boost::math::chi_squared_distribution<double> d(dof);
  return boost::math::quantile(boost::math::complement(d, p));
}

double nonCentralChiSquareCdf(int dof, double lambda, double x) {
  requireDof(dof);
  if (!(lambda >= 0.0) || !std::isfinite(lambda)) throw std::invalid_argument("non-centrality must be finite and >= 0");
  if (x <= 0) return 0.0;
  if (lambda == 0.0) return boost::math::cdf(boost::math::chi_squared_distribution<double>(dof), x);
  const boost::math::non_central_chi_squared_distribution<double> d(dof, lambda);
  return boost::math::cdf(d, x);
}

double nonCentralityForCdf(int dof, double x, double p) {
  requireDof(dof);
  requireProbability(p, "nonCentralityForCdf");
  if (nonCentralChiSquareCdf(dof, 0.0, x) <= p) return 0.0;
  double lo = 0.0, hi = 1.0;
  while (nonCentralChiSquareCdf(dof, hi, x) > p) hi *= 2.0;  // CDF decreases with λ
  while (hi - lo > kLambdaRelTol * hi) {
    const double mid = 0.5 * (lo + hi);
    (nonCentralChiSquareCdf(dof, mid, x) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace skylane::integrity
