// The double-precision normal tail inverse (Wichura's AS 241) against Boost's erfc_inv.
#include "integrity/stats.hpp"

#include "tests/test_util.hpp"

#include <cmath>

namespace skylane::integrity {
namespace {

/// The stated accuracy bound of normalTailInverse: absolute near x = 0, relative beyond |x| = 1.
constexpr double kTailInverseTol = 1e-15;

TEST(NormalTailInverse, MatchesBoostWithinTheStatedBoundFromTheFarTailToTheCentre) {
  // GIVEN p on a logarithmic grid from 1e-300 to 0.5 (40 points a decade) and its mirror 1 − p
  double worst = 0.0, worst_p = 0.0;
  for (double lg = -300.0; lg <= std::log10(0.5); lg += 0.025) {
    const double p = std::pow(10.0, lg);
    for (const double pp : {p, 1.0 - p}) {
      if (!(pp > 0.0 && pp < 1.0)) continue;
      // WHEN both are evaluated THEN they agree within the bound
      const double x = normalTailInverseReference(pp);
      const double err = std::abs(normalTailInverse(pp) - x) / std::max(1.0, std::abs(x));
      if (err > worst) worst = err, worst_p = pp;
      ASSERT_LE(err, kTailInverseTol) << "p = " << pp;
    }
  }
  std::printf("AS 241 vs Boost erfc_inv: worst scaled error %.2e at p = %.3g\n", worst, worst_p);
}

TEST(NormalTailAndDensity, MatchLongDoubleErfcAndExpWithinTheStatedBound) {
  // GIVEN z from 0 to 37 in steps of 1/1024 (every branch of Cody's approximations: x = z/√2
  // below 0.46875, up to 4, beyond), the long-double erfc and exp as reference
  double worst_tail = 0.0, worst_density = 0.0;
  for (int k = 0; k <= 37 * 1024; ++k) {
    const double z = k / 1024.0;
    const long double zl = z;
    const long double tail = 0.5L * std::erfc(zl / std::sqrt(2.0L));
    const long double density = std::exp(-0.5L * zl * zl) / std::sqrt(2.0L * 3.14159265358979323846264338327950288L);
    // WHEN both are evaluated with one exponential THEN each is within 2e-15 relative
    const TailAndDensity td = normalTailAndDensity(z);
    const double e_tail = static_cast<double>(std::abs((td.tail - tail) / tail));
    const double e_density = static_cast<double>(std::abs((td.density - density) / density));
    worst_tail = std::max(worst_tail, e_tail);
    worst_density = std::max(worst_density, e_density);
    ASSERT_LE(e_tail, 2e-15) << "z = " << z;
    ASSERT_LE(e_density, 2e-15) << "z = " << z;
  }
  std::printf("Q and phi with one exp: worst relative error %.2e / %.2e\n", worst_tail, worst_density);
  EXPECT_NEAR(normalTailAndDensity(5.199337582192817).tail, 1e-7, 1e-21);  // the known quantile, backwards
}

TEST(NormalTailInverse, GivesKnownQuantilesOverTheRangeAraimUses) {
  // Q⁻¹(p) = √2·erfc⁻¹(2p) to 30 digits (mpmath 1.3, mp.dps = 30), p from 1e-15 to 0.5.
  struct Case {
    double p, x;
  };
  const Case cases[] = {{1e-15, 7.94134532617099678355892555338}, {1e-9, 5.99780701500768687156231221737},
                        {1e-7, 5.19933758219281693158734727875},  {1e-5, 4.26489079392282462849852469875},
                        {1e-3, 3.09023230616781354154039983011},  {0.025, 1.95996398454005423552459443052},
                        {0.3, 0.524400512708040784038289325025}, {0.5, 0.0}};
  for (const Case& c : cases) {
    EXPECT_NEAR(normalTailInverse(c.p), c.x, kTailInverseTol * std::max(1.0, c.x)) << c.p;
    EXPECT_NEAR(normalTailInverseReference(c.p), c.x, 2e-15 * std::max(1.0, c.x)) << c.p;
  }
}

TEST(NormalTailInverse, IsTheInverseOfTheTailAndAntisymmetric) {
  for (const double p : {1e-12, 3.9e-6 / 130.0, 0.075, 0.3, 0.5}) {
    const double x = normalTailInverse(p);
    EXPECT_NEAR(normalTail(x) / p, 1.0, 1e-13) << p;
    const double pc = 1.0 - p, p_exact = 1.0 - pc;  // 1 − p rounds; its complement is exact (Sterbenz)
    EXPECT_NEAR(normalTailInverse(pc), -normalTailInverse(p_exact), kTailInverseTol * std::max(1.0, std::abs(x))) << p;
  }
  EXPECT_EQ(normalTailInverse(0.5), 0.0);
  EXPECT_THROW((void)normalTailInverse(0.0), std::invalid_argument);
  EXPECT_THROW((void)normalTailInverse(1.0), std::invalid_argument);
}

}  // namespace
}  // namespace skylane::integrity
