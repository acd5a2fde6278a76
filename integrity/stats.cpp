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

double normalTailInverse(double p) {
  requireProbability(p, "normalTailInverse");
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
