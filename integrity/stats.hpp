#pragma once
/// \file
/// \brief The few distributions integrity needs: the normal tail Q, its inverse, chi-square and
/// non-central chi-square quantiles (computed with Boost.Math, not tabled).

namespace skylane::integrity {

/// \brief Q(x) = 1 − Φ(x), the standard normal upper tail (via erfc, accurate to 1e-300).
[[nodiscard]] double normalTail(double x);
/// \brief Q(z) and the density φ(z) for z ≥ 0 with one exponential: φ from exp(−z²/2) with z²
/// split exactly by a fused multiply-add, Q = φ·(√(2π)/2)·e^{x²}erfc(x) (x = z/√2) from W. J.
/// Cody's rational Chebyshev approximations ("Rational Chebyshev approximations for the error
/// function", Math. Comp. 23(107) 631–637, 1969). Accuracy (tests/integrity/stats_test.cpp,
/// against erfc and exp): relative 2e-15 for both, z in [0, 37]. What the ARAIM PL solver
/// evaluates at every term and iterate.
struct TailAndDensity {
  double tail = 0.0, density = 0.0;
};
[[nodiscard]] TailAndDensity normalTailAndDensity(double z);
/// \brief Q⁻¹(p): the x with Q(x) = p, for p in (0, 1), in double precision by Wichura's AS 241
/// (Applied Statistics 37(3), 1988). Accuracy (tests/integrity/stats_test.cpp, against Boost's
/// erfc_inv): |error| ≤ 1e-15·max(1, |x|) for p in [1e-300, 1 − 1e-16].
[[nodiscard]] double normalTailInverse(double p);
/// \brief Q⁻¹(p) through Boost's erfc_inv (computed in long double): the slow reference the
/// fast one is tested against.
[[nodiscard]] double normalTailInverseReference(double p);
/// \brief The x with P(χ²_dof > x) = p (upper-tail quantile).
[[nodiscard]] double chiSquareUpperQuantile(int dof, double p);
/// \brief P(χ²_dof(λ) ≤ x): the non-central chi-square CDF with non-centrality λ.
[[nodiscard]] double nonCentralChiSquareCdf(int dof, double lambda, double x);
/// \brief The non-centrality λ with P(χ²_dof(λ) ≤ x) = p (bisection on the monotone CDF).
[[nodiscard]] double nonCentralityForCdf(int dof, double x, double p);

}  // namespace skylane::integrity
