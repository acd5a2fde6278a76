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
