#include "integrity/ins/ekf.hpp"
#include "integrity/ins/risk_allocation.hpp"
#include "integrity/ins/strapdown.hpp"
#include "maps/geodesy.hpp"
#include "tests/test_util.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace skylane::integrity {
namespace {

// --- Risk allocation (J. Zhao & D. Song, Acta Aeronautica et Astronautica Sinica 45(7), 2024) ---

/// Half a unit in the 5th significant digit of `printed`: the paper prints five digits.
double halfUnitOf5Digits(double printed) {
  const double exponent = std::floor(std::log10(std::abs(printed)));
  return 0.5 * std::pow(10.0, exponent - 4.0);
}

/// Binomial C(n, k) p^k (1 − p)^(n − k), written out independently of the product.
double binomialTerm(int n, int k, double p) {
  double c = 1.0;
  for (int j = 1; j <= k; ++j) c = c * (n - k + j) / j;
  return c * std::pow(p, k) * std::pow(1.0 - p, n - k);
}

/// Two or more of n satellites faulty.
double multiPrior(int n, double p) {
  double sum = 0.0;
  for (int k = 2; k <= n; ++k) sum += binomialTerm(n, k, p);
  return sum;
}

constexpr int kSats = 10;  // Zhao & Song's example: K = 10 satellites in view
/// Relative tolerance for priors and budgets against an independent closed form (a few rounding
/// errors of sums of ≤ 10 terms).
constexpr double kRelTol = 1e-12;

double prior(const std::array<double, kNumInsFaultModes>& p, InsFaultMode m) { return p[static_cast<int>(m)]; }

TEST(InsRiskAllocation, Class1PriorsMatchThePaperToFiveDigits) {
  const RiskAllocationConfig cfg;  // p_sat 1e-5, p_imu 1e-3
  const auto p = faultModePriors(kSats, DetectionClass::kGnssAlone, cfg);
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssSingle), 9.9991e-5, halfUnitOf5Digits(9.9991e-5));
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssMulti), 4.4998e-9, halfUnitOf5Digits(4.4998e-9));
  // The IMU modes do not exist in class 1.
  EXPECT_EQ(prior(p, InsFaultMode::kImu), 0.0);
  EXPECT_EQ(prior(p, InsFaultMode::kGnssSingleImu), 0.0);
  EXPECT_EQ(prior(p, InsFaultMode::kGnssMultiImu), 0.0);
  // Independent binomial forms; the three modes exhaust the outcomes.
  EXPECT_NEAR(prior(p, InsFaultMode::kFaultFree), binomialTerm(kSats, 0, 1e-5), 1e-15);
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssSingle), binomialTerm(kSats, 1, 1e-5), kRelTol * 1e-4);
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssMulti), multiPrior(kSats, 1e-5), kRelTol * 4.5e-9);
  EXPECT_NEAR(p[0] + p[1] + p[2], 1.0, 1e-15);
}

TEST(InsRiskAllocation, Class2PriorsMatchThePaperToFiveDigits) {
  const RiskAllocationConfig cfg;
  const auto p = faultModePriors(kSats, DetectionClass::kIntegrated, cfg);
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssSingle), 9.9891e-5, halfUnitOf5Digits(9.9891e-5));
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssMulti), 4.4953e-9, halfUnitOf5Digits(4.4953e-9));
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssSingleImu), 9.9991e-8, halfUnitOf5Digits(9.9991e-8));
  // Independent: GNSS and IMU faults independent (Eq. (7)).
  const double q = 1e-3;
  EXPECT_NEAR(prior(p, InsFaultMode::kFaultFree), binomialTerm(kSats, 0, 1e-5) * (1 - q), 1e-15);
  EXPECT_NEAR(prior(p, InsFaultMode::kImu), binomialTerm(kSats, 0, 1e-5) * q, kRelTol * 1e-3);
  EXPECT_NEAR(prior(p, InsFaultMode::kGnssMultiImu), multiPrior(kSats, 1e-5) * q, kRelTol * 4.5e-12);
  double sum = 0.0;
  for (double v : p) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-15);  // with GMI the six modes exhaust the outcomes

  RiskAllocationConfig paper = cfg;
  paper.include_gm_imu = false;
  EXPECT_EQ(prior(faultModePriors(kSats, DetectionClass::kIntegrated, paper), InsFaultMode::kGnssMultiImu), 0.0);
}

/// Checks the invariants every allocation must keep: the budgets of the considered modes sum to the
/// direction's budget, a mode without PL gets its prior, the conditional is budget / prior.
void expectConsistent(const RiskAllocation& a) {
  double sum = 0.0;
  for (int i = 0; i < kNumInsFaultModes; ++i) {
    const ModeBudget& b = a.modes[i];
    if (!b.considered) continue;
    sum += b.budget;
    if (!b.needs_pl) {
      EXPECT_DOUBLE_EQ(b.budget, b.prior) << faultModeName(static_cast<InsFaultMode>(i));
    }
    EXPECT_NEAR(b.conditional, std::min(1.0, b.budget / b.prior), 1e-15 * b.conditional + 1e-300)
        << faultModeName(static_cast<InsFaultMode>(i));
  }
  EXPECT_NEAR(sum, a.direction_budget, 1e-12 * a.direction_budget);
}

TEST(InsRiskAllocation, PaperAllocationGivesFourEqualShares) {
  // GIVEN the paper's class 2 without GMI, vertical budget 0.5 × 1e-7
  RiskAllocationConfig cfg;
  cfg.include_gm_imu = false;
  // WHEN the vertical budget is split
  const RiskAllocation a = allocateRisk(kSats, DetectionClass::kIntegrated, true, cfg);
  // THEN GM (prior 4.4953e-9 ≤ 1e-7 / 20) takes its prior, the four others share the rest.
  EXPECT_DOUBLE_EQ(a.direction_budget, 5e-8);
  const ModeBudget& gm = a.of(InsFaultMode::kGnssMulti);
  EXPECT_FALSE(gm.needs_pl);
  EXPECT_DOUBLE_EQ(gm.budget, gm.prior);
  EXPECT_DOUBLE_EQ(gm.conditional, 1.0);
  EXPECT_FALSE(a.of(InsFaultMode::kGnssMultiImu).considered);
  const double share = (5e-8 - 0.999 * multiPrior(kSats, 1e-5)) / 4.0;
  for (InsFaultMode m : {InsFaultMode::kFaultFree, InsFaultMode::kGnssSingle, InsFaultMode::kImu,
                         InsFaultMode::kGnssSingleImu}) {
    const ModeBudget& b = a.of(m);
    EXPECT_TRUE(b.needs_pl) << faultModeName(m);
    EXPECT_NEAR(b.budget, 1.1376e-8, halfUnitOf5Digits(1.1376e-8)) << faultModeName(m);
    EXPECT_NEAR(b.budget, share, kRelTol * share) << faultModeName(m);
  }
  // Conditional risks: GSI prior 9.9991e-8, so P(HMI | GSI) = 1.1376e-8 / 9.9991e-8.
  EXPECT_NEAR(a.of(InsFaultMode::kGnssSingleImu).conditional, share / (binomialTerm(kSats, 1, 1e-5) * 1e-3), 1e-12);
  expectConsistent(a);
}

TEST(InsRiskAllocation, GmiModeTakesItsPriorAndShrinksTheShares) {
  const RiskAllocationConfig cfg;  // include_gm_imu = true
  const RiskAllocation a = allocateRisk(kSats, DetectionClass::kIntegrated, true, cfg);
  const double p_gm = 0.999 * multiPrior(kSats, 1e-5);
  const double p_gmi = 1e-3 * multiPrior(kSats, 1e-5);
  const double share = (5e-8 - p_gm - p_gmi) / 4.0;
  const ModeBudget& gmi = a.of(InsFaultMode::kGnssMultiImu);
  EXPECT_TRUE(gmi.considered);
  EXPECT_FALSE(gmi.needs_pl);
  EXPECT_NEAR(gmi.budget, p_gmi, kRelTol * p_gmi);
  for (InsFaultMode m : {InsFaultMode::kFaultFree, InsFaultMode::kGnssSingle, InsFaultMode::kImu,
                         InsFaultMode::kGnssSingleImu}) {
    EXPECT_NEAR(a.of(m).budget, share, kRelTol * share) << faultModeName(m);
    EXPECT_NEAR(a.of(m).budget, 1.13751e-8, 0.5e-13) << faultModeName(m);  // six digits: 1.13751e-8
  }
  expectConsistent(a);
}

TEST(InsRiskAllocation, Class1SharesBetweenFaultFreeAndSingle) {
  const RiskAllocationConfig cfg;
  for (bool vertical : {false, true}) {
    const RiskAllocation a = allocateRisk(kSats, DetectionClass::kGnssAlone, vertical, cfg);
    EXPECT_DOUBLE_EQ(a.direction_budget, 5e-8);  // vertical_share 0.5
    EXPECT_FALSE(a.of(InsFaultMode::kImu).considered);
    EXPECT_FALSE(a.of(InsFaultMode::kGnssSingleImu).considered);
    EXPECT_FALSE(a.of(InsFaultMode::kGnssMultiImu).considered);
    EXPECT_FALSE(a.of(InsFaultMode::kGnssMulti).needs_pl);
    const double share = (5e-8 - multiPrior(kSats, 1e-5)) / 2.0;
    EXPECT_NEAR(a.of(InsFaultMode::kFaultFree).budget, share, kRelTol * share);
    EXPECT_NEAR(a.of(InsFaultMode::kGnssSingle).budget, share, kRelTol * share);
    EXPECT_NEAR(a.of(InsFaultMode::kGnssSingle).conditional, share / binomialTerm(kSats, 1, 1e-5), 1e-15);
    expectConsistent(a);
  }
}

TEST(InsRiskAllocation, BudgetsSumToTheDirectionForManyGeometries) {
  // Property over K and an uneven split: the budgets always account for the whole direction budget.
  RiskAllocationConfig cfg;
  cfg.vertical_share = 0.3;
  for (int k = 1; k <= 40; ++k) {
    for (auto det : {DetectionClass::kGnssAlone, DetectionClass::kIntegrated}) {
      for (bool vertical : {false, true}) {
        const RiskAllocation a = allocateRisk(k, det, vertical, cfg);
        EXPECT_NEAR(a.direction_budget, vertical ? 3e-8 : 7e-8, 1e-22);
        expectConsistent(a);
      }
    }
  }
}

TEST(InsRiskAllocation, BadInputsThrowNamingTheProblem) {
  const RiskAllocationConfig cfg;
  std::string msg = test::messageOf<std::invalid_argument>(
      [&] { (void)faultModePriors(0, DetectionClass::kIntegrated, cfg); });
  EXPECT_NE(msg.find("number of satellites"), std::string::npos) << msg;
  msg = test::messageOf<std::invalid_argument>([&] { (void)allocateRisk(-3, DetectionClass::kGnssAlone, true, cfg); });
  EXPECT_NE(msg.find("number of satellites"), std::string::npos) << msg;

  RiskAllocationConfig bad = cfg;
  bad.p_sat = 1.0;
  msg = test::messageOf<std::invalid_argument>([&] { (void)faultModePriors(10, DetectionClass::kGnssAlone, bad); });
  EXPECT_NE(msg.find("p_sat"), std::string::npos) << msg;
  bad.p_sat = std::numeric_limits<double>::quiet_NaN();
  msg = test::messageOf<std::invalid_argument>([&] { (void)faultModePriors(10, DetectionClass::kGnssAlone, bad); });
  EXPECT_NE(msg.find("p_sat"), std::string::npos) << msg;

  bad = cfg;
  bad.p_imu = -0.1;
  msg = test::messageOf<std::invalid_argument>([&] { (void)faultModePriors(10, DetectionClass::kIntegrated, bad); });
  EXPECT_NE(msg.find("p_imu"), std::string::npos) << msg;

  bad = cfg;
  bad.i_req = 0.0;
  msg = test::messageOf<std::invalid_argument>([&] { (void)allocateRisk(10, DetectionClass::kIntegrated, true, bad); });
  EXPECT_NE(msg.find("i_req"), std::string::npos) << msg;

  // Priors of the negligible modes larger than the budget: a sentence, not a negative share.
  // GM ≈ 45 p² = 7e-10 passes as negligible (≤ 0.9 × 1e-9) but exceeds the vertical 5e-10.
  bad = cfg;
  bad.i_req = 1e-9;
  bad.negligible_fraction = 0.9;
  bad.p_sat = 3.94e-6;
  msg = test::messageOf<std::invalid_argument>([&] { (void)allocateRisk(10, DetectionClass::kIntegrated, true, bad); });
  EXPECT_NE(msg.find("exceed"), std::string::npos) << msg;
}

TEST(InsRiskAllocation, ModeNamesAreThePapers) {
  EXPECT_EQ(faultModeName(InsFaultMode::kFaultFree), "FF");
  EXPECT_EQ(faultModeName(InsFaultMode::kGnssSingle), "GS");
  EXPECT_EQ(faultModeName(InsFaultMode::kGnssMulti), "GM");
  EXPECT_EQ(faultModeName(InsFaultMode::kImu), "I");
  EXPECT_EQ(faultModeName(InsFaultMode::kGnssSingleImu), "GSI");
  EXPECT_EQ(faultModeName(InsFaultMode::kGnssMultiImu), "GMI");
}

}  // namespace

namespace ins {
namespace {

// --- Strapdown (Groves 2013 §5.2, §2.4.7) ------------------------------------------------------

/// Somigliana normal gravity on the WGS-84 ellipsoid (NIMA TR8350.2 Eq. 4-1).
double somigliana(double lat_rad) {
  constexpr double kGammaE = 9.7803253359;     // at the equator [m/s²]
  constexpr double kK = 0.00193185265241;      // (b γ_p − a γ_e) / (a γ_e)
  constexpr double kE2 = 0.00669437999013;     // first eccentricity squared
  const double s2 = std::sin(lat_rad) * std::sin(lat_rad);
  return kGammaE * (1.0 + kK * s2) / std::sqrt(1.0 - kE2 * s2);
}

/// The J2 field lacks the higher zonal terms of the normal field: within 2e-3 m/s².
constexpr double kGravityTol_mps2 = 2e-3;

TEST(InsStrapdown, GravityMagnitudeMatchesSomiglianaAtEquatorPoleAndBetween) {
  const double b = maps::kWgs84A_m * (1.0 - maps::kWgs84F);
  const Eigen::Vector3d g_eq = gravityEcef(Eigen::Vector3d(maps::kWgs84A_m, 0.0, 0.0));
  const Eigen::Vector3d g_pole = gravityEcef(Eigen::Vector3d(0.0, 0.0, b));
  EXPECT_NEAR(g_eq.norm(), 9.7803, kGravityTol_mps2);
  EXPECT_NEAR(g_pole.norm(), 9.8322, kGravityTol_mps2);
  // Direction: straight down the x (equator) and z (pole) axes.
  EXPECT_TRUE(test::nearVec(g_eq / g_eq.norm(), Eigen::Vector3d(-1, 0, 0), 1e-12));
  EXPECT_TRUE(test::nearVec(g_pole / g_pole.norm(), Eigen::Vector3d(0, 0, -1), 1e-12));
  for (double lat_deg = -80.0; lat_deg <= 80.0; lat_deg += 10.0) {
    const maps::Geodetic p{maps::deg2rad(lat_deg), maps::deg2rad(20.0), 0.0};
    const Eigen::Vector3d g = gravityEcef(maps::geodeticToEcef(p));
    EXPECT_NEAR(g.norm(), somigliana(p.lat_rad), kGravityTol_mps2) << lat_deg;
    // Normal gravity is normal to the ellipsoid: the J2 field is within 1e-4 rad (20″) of it.
    const Eigen::Vector3d down = -maps::rotationEcefToEnu(p.lat_rad, p.lon_rad).row(2).transpose();
    EXPECT_GT(g.normalized().dot(down), std::cos(1e-4)) << lat_deg;
  }
  // Gravity weakens with height by about 3.086e-6 s⁻² (free-air gradient).
  const maps::Geodetic low{maps::deg2rad(45.0), 0.0, 0.0}, high{maps::deg2rad(45.0), 0.0, 1000.0};
  EXPECT_NEAR(gravityEcef(maps::geodeticToEcef(low)).norm() - gravityEcef(maps::geodeticToEcef(high)).norm(),
              3.086e-3, 0.05e-3);
}

/// Rodrigues' formula written out: I + sin θ/θ [k×] + (1 − cos θ)/θ² [k×]².
Eigen::Matrix3d rodrigues(const Eigen::Vector3d& phi) {
  const double t = phi.norm();
  Eigen::Matrix3d k;
  k << 0, -phi.z(), phi.y(), phi.z(), 0, -phi.x(), -phi.y(), phi.x(), 0;
  return Eigen::Matrix3d::Identity() + std::sin(t) / t * k + (1.0 - std::cos(t)) / (t * t) * k * k;
}

double maxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

TEST(InsStrapdown, ExpAndLogAreInverseAndMatchRodrigues) {
  std::mt19937_64 rng(20240701);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 500; ++i) {
    Eigen::Vector3d dir(u(rng), u(rng), u(rng));
    if (dir.norm() < 1e-3) continue;
    const Eigen::Vector3d phi = dir.normalized() * (3.0 * std::abs(u(rng)) + 1e-6);  // |φ| < 3 (< π)
    const Eigen::Matrix3d R = expSo3(phi);
    EXPECT_LT(maxAbs(R - rodrigues(phi)), 1e-14) << i;
    EXPECT_LT(maxAbs(R.transpose() * R - Eigen::Matrix3d::Identity()), 1e-14) << i;
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14) << i;
    EXPECT_TRUE(test::nearVec(logSo3(R), phi, 1e-11)) << i;
  }
  // The skew matrix is the cross product.
  const Eigen::Vector3d a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_TRUE(test::nearVec(skew(a) * b, a.cross(b), 1e-15));
  // Tiny angles: first order.
  const Eigen::Vector3d tiny(1e-14, -2e-14, 3e-14);
  EXPECT_TRUE(test::nearVec(logSo3(expSo3(tiny)), tiny, 1e-20));
}

/// A random state within 10 km of the WGS-84 surface.
NavState randomState(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const maps::Geodetic g{u(rng) * 1.5, u(rng) * M_PI, 5000.0 + 5000.0 * u(rng)};
  NavState x;
  x.r_ecef_m = maps::geodeticToEcef(g);
  x.v_ecef_mps = 100.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  x.C_ecef_body = expSo3(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 1.7);
  return x;
}

TEST(InsStrapdown, BodyIncrementsInvertTheMechanisation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const double dt = 0.01 * (1.0 + std::abs(u(rng)));
    const NavState from = randomState(rng);
    NavState to = from;
    to.C_ecef_body = expSo3(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.05) * from.C_ecef_body;
    to.v_ecef_mps += Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.3;
    to.r_ecef_m += 0.5 * dt * (from.v_ecef_mps + to.v_ecef_mps);
    Eigen::Vector3d dtheta, dv;
    bodyIncrements(from, to, dt, dtheta, dv);
    const NavState got = mechanise(from, dtheta, dv, dt);
    EXPECT_LT(maxAbs(got.C_ecef_body - to.C_ecef_body), 1e-12) << i;
    EXPECT_TRUE(test::nearVec(got.v_ecef_mps, to.v_ecef_mps, 1e-9)) << i;
    // Position by the trapezoid (file comment of strapdown.hpp).
    EXPECT_TRUE(test::nearVec(got.r_ecef_m, to.r_ecef_m, 1e-8)) << i;
  }
}

TEST(InsStrapdown, VehicleAtRestStaysPutFor100Seconds) {
  // GIVEN a vehicle at rest on the ground at 47° N, levelled and heading 30°: its gyros see the
  // Earth rate, its accelerometers the reaction to gravity (both in the body frame).
  const maps::Geodetic site{maps::deg2rad(47.0), maps::deg2rad(8.5), 0.0};
  NavState x;
  x.r_ecef_m = maps::geodeticToEcef(site);
  const Eigen::Matrix3d C_ecef_enu = maps::rotationEcefToEnu(site.lat_rad, site.lon_rad).transpose();
  const double psi = maps::deg2rad(30.0);
  Eigen::Matrix3d C_enu_body;  // columns: forward, left, up (FLU) in ENU
  C_enu_body.col(0) << std::sin(psi), std::cos(psi), 0.0;
  C_enu_body.col(1) << -std::cos(psi), std::sin(psi), 0.0;
  C_enu_body.col(2) << 0.0, 0.0, 1.0;
  x.C_ecef_body = C_ecef_enu * C_enu_body;
  const NavState start = x;
  constexpr double kDt = 0.01;
  const Eigen::Vector3d f_body = -(x.C_ecef_body.transpose() * gravityEcef(x.r_ecef_m));
  const Eigen::Vector3d w_body = x.C_ecef_body.transpose() * Eigen::Vector3d(0.0, 0.0, kEarthRate_radps);
  // WHEN 100 s at 100 Hz are mechanised
  for (int i = 0; i < 10000; ++i) x = mechanise(x, w_body * kDt, f_body * kDt, kDt);
  // THEN position, velocity and attitude have not moved.
  EXPECT_LT((x.r_ecef_m - start.r_ecef_m).norm(), 1e-3);
  EXPECT_LT(x.v_ecef_mps.norm(), 1e-5);
  constexpr double kRoundoff10kSteps = 1e-10;  // 10⁴ products of rotations, ~1e-16 each
  EXPECT_LT(maxAbs(x.C_ecef_body - start.C_ecef_body), kRoundoff10kSteps);

  // Without the Earth rate on the gyros the body turns against the Earth and the vehicle drifts
  // away: the check above is able to fail.
  NavState y = start;
  for (int i = 0; i < 10000; ++i) y = mechanise(y, Eigen::Vector3d::Zero(), f_body * kDt, kDt);
  EXPECT_GT((y.r_ecef_m - start.r_ecef_m).norm(), 1.0);
}

// --- EKF updates ------------------------------------------------------------------------------

/// Heading (clockwise from north) of the body's forward axis, computed here from the geodesy.
double headingOf(const NavState& x) {
  const maps::Geodetic g = maps::ecefToGeodetic(x.r_ecef_m);
  const Eigen::Vector3d f = maps::rotationEcefToEnu(g.lat_rad, g.lon_rad) * x.C_ecef_body.col(0);
  return std::atan2(f.x(), f.y());
}

/// Numeric ∂ψ/∂φ for C → Exp(φ)·C (central differences at √ε-ish steps).
Eigen::RowVector3d numericHeadingJacobian(const NavState& x) {
  constexpr double kStep = 1e-6;
  Eigen::RowVector3d J;
  for (int i = 0; i < 3; ++i) {
    NavState plus = x, minus = x;
    plus.C_ecef_body = expSo3(Eigen::Vector3d::Unit(i) * kStep) * x.C_ecef_body;
    minus.C_ecef_body = expSo3(-Eigen::Vector3d::Unit(i) * kStep) * x.C_ecef_body;
    J(i) = std::remainder(headingOf(plus) - headingOf(minus), 2.0 * M_PI) / (2.0 * kStep);
  }
  return J;
}

NavState stateAt(double heading_deg, double pitch_deg, double roll_deg) {
  const maps::Geodetic site{maps::deg2rad(47.4), maps::deg2rad(8.5), 500.0};
  NavState x;
  x.r_ecef_m = maps::geodeticToEcef(site);
  x.v_ecef_mps.setZero();
  const Eigen::Matrix3d C_ecef_enu = maps::rotationEcefToEnu(site.lat_rad, site.lon_rad).transpose();
  // Body FLU → ENU: yaw about up (π/2 − ψ), pitch nose up (about −left… i.e. −y), roll right wing down (+x).
  const Eigen::Matrix3d C_enu_body =
      (Eigen::AngleAxisd(M_PI / 2 - maps::deg2rad(heading_deg), Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(-maps::deg2rad(pitch_deg), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(maps::deg2rad(roll_deg), Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  x.C_ecef_body = C_ecef_enu * C_enu_body;
  return x;
}

EkfConfig testConfig() {
  EkfConfig cfg;
  cfg.initial_attitude_rad = maps::deg2rad(3.0);
  cfg.heading_noise_rad = maps::deg2rad(2.0);
  cfg.initial_position_m = 5.0;
  cfg.baro_bias_m = 3.0;
  cfg.baro_noise_m = 0.3;
  // Tiny elsewhere: only the states the update sees matter.
  cfg.initial_velocity_mps = 1e-3;
  cfg.accel_bias_mps2 = 1e-6;
  cfg.gyro_bias_radps = 1e-9;
  return cfg;
}

TEST(InsEkf, HeadingUpdateMovesByTheKalmanFraction) {
  struct Case {
    const char* name;
    double heading_deg, pitch_deg, roll_deg;
    double offset_deg;  // measurement − estimate
    double tol_rad;     // second-order terms of the attitude correction: ~ (K ν)²
  };
  const Case cases[] = {
      {"level", 30.0, 0.0, 0.0, 1.0, 1e-6},
      {"level across north", 179.5, 0.0, 0.0, 1.0, 1e-6},  // measurement wraps past ±180°
      {"pitched and rolled", -60.0, 20.0, 10.0, 0.01, 1e-8},
      {"steep climb", 100.0, 55.0, -25.0, 0.01, 1e-8},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const EkfConfig cfg = testConfig();
    InsEkf ekf(cfg, stateAt(c.heading_deg, c.pitch_deg, c.roll_deg), 0.0, 0.0);
    const double before = ekf.heading_rad();
    EXPECT_NEAR(std::remainder(before - maps::deg2rad(c.heading_deg), 2 * M_PI), 0.0, 1e-12);
    // Independent prior heading variance: numeric Jacobian through the attitude covariance.
    const Eigen::RowVector3d J = numericHeadingJacobian(ekf.nav());
    const double P_psi = J * ekf.covariance().block<3, 3>(kAtt, kAtt) * J.transpose();
    const double R = cfg.heading_noise_rad * cfg.heading_noise_rad;
    const double nu = maps::deg2rad(c.offset_deg);
    ekf.updateHeading(std::remainder(before + nu, 2 * M_PI));
    const double moved = std::remainder(ekf.heading_rad() - before, 2 * M_PI);
    EXPECT_NEAR(moved, P_psi / (P_psi + R) * nu, c.tol_rad);
    // Posterior heading variance P − P²/(P + R) (through the prior's Jacobian, as the filter's H).
    const double P_after = J * ekf.covariance().block<3, 3>(kAtt, kAtt) * J.transpose();
    EXPECT_NEAR(P_after, P_psi - P_psi * P_psi / (P_psi + R), 1e-6 * P_psi);
    // Position does not move on a heading update (no correlation yet).
    EXPECT_LT((ekf.nav().r_ecef_m - stateAt(c.heading_deg, c.pitch_deg, c.roll_deg).r_ecef_m).norm(), 1e-9);
  }
}

TEST(InsEkf, AidingFarFromThePredictionIsRefusedAndLeavesTheStateAlone) {
  const EkfConfig cfg = testConfig();
  InsEkf ekf(cfg, stateAt(45.0, 0.0, 0.0), 0.0, 0.0);
  const NavState before = ekf.nav();
  const maps::Geodetic g0 = maps::ecefToGeodetic(before.r_ecef_m);
  const StateMatrix P = ekf.covariance();
  // A barometer 1 km off (σ_S ≈ 6 m here) and a heading 90° off (σ ≈ 3°) fail the χ²(1) gate
  EXPECT_FALSE(ekf.updateBaro(g0.h_ell_m + 1000.0));
  EXPECT_FALSE(ekf.updateHeading(std::remainder(ekf.heading_rad() + M_PI / 2.0, 2 * M_PI)));
  EXPECT_EQ(ekf.nav().r_ecef_m, before.r_ecef_m);
  EXPECT_EQ(ekf.nav().C_ecef_body, before.C_ecef_body);
  EXPECT_EQ(ekf.covariance(), P);
  // while one 2 m off is taken
  EXPECT_TRUE(ekf.updateBaro(g0.h_ell_m + 2.0));
}

TEST(InsEkf, BaroUpdateSplitsTheInnovationBetweenHeightAndBaroBias) {
  const EkfConfig cfg = testConfig();
  const NavState x0 = stateAt(45.0, 0.0, 0.0);
  InsEkf ekf(cfg, x0, 0.0, 0.0);
  const maps::Geodetic g0 = maps::ecefToGeodetic(ekf.nav().r_ecef_m);
  // Independent: the geodetic up from latitude and longitude.
  const Eigen::Vector3d up(std::cos(g0.lat_rad) * std::cos(g0.lon_rad), std::cos(g0.lat_rad) * std::sin(g0.lon_rad),
                           std::sin(g0.lat_rad));
  const StateMatrix P = ekf.covariance();
  const double P_h = up.dot(P.block<3, 3>(kPos, kPos) * up);
  const double P_b = P(kBaro, kBaro);
  const double R = cfg.baro_noise_m * cfg.baro_noise_m;
  const double S = P_h + P_b + R;
  const double nu = 2.0;
  ekf.updateBaro(g0.h_ell_m + ekf.baroBias_m() + nu);
  const maps::Geodetic g1 = maps::ecefToGeodetic(ekf.nav().r_ecef_m);
  EXPECT_NEAR(g1.h_ell_m - g0.h_ell_m, P_h / S * nu, 1e-6);
  EXPECT_NEAR(ekf.baroBias_m(), P_b / S * nu, 1e-9);
  // The correction is along the geodetic up only: no horizontal move.
  const Eigen::Vector3d d_enu =
      maps::rotationEcefToEnu(g0.lat_rad, g0.lon_rad) * (ekf.nav().r_ecef_m - x0.r_ecef_m);
  EXPECT_NEAR(d_enu.x(), 0.0, 1e-8);  // ECEF coordinates ~6.4e6 m: one ulp ≈ 1e-9 m
  EXPECT_NEAR(d_enu.y(), 0.0, 1e-8);
  // Posterior height variance and its (negative) correlation with the baro bias.
  const StateMatrix Pa = ekf.covariance();
  EXPECT_NEAR(up.dot(Pa.block<3, 3>(kPos, kPos) * up), P_h - P_h * P_h / S, 1e-9);
  EXPECT_NEAR(up.dot(Pa.block<3, 1>(kPos, kBaro)), -P_h * P_b / S, 1e-9);
  EXPECT_NEAR(Pa(kBaro, kBaro), P_b - P_b * P_b / S, 1e-9);
}

TEST(InsEkf, ZeroCovarianceRateIsRejected) {
  EkfConfig cfg;
  cfg.covariance_rate_hz = 0.0;
  const std::string msg = test::messageOf<std::invalid_argument>([&] { (void)InsEkf(cfg, NavState{}, 0.0, 0.0); });
  EXPECT_NE(msg.find("covariance rate"), std::string::npos) << msg;
}

}  // namespace
}  // namespace ins
}  // namespace skylane::integrity
