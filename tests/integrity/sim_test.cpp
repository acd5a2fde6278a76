#include "integrity/sim/run.hpp"
#include "integrity/sim/scenario.hpp"
#include "integrity/sim/sensors.hpp"
#include "integrity/sim/trajectory.hpp"
#include "maps/geodesy.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace skylane::integrity::sim {
namespace {

constexpr double kG_mps2 = 9.80665;  // standard gravity, the coordinated-turn bank's g

const maps::Geodetic kZurich{maps::deg2rad(47.3769), maps::deg2rad(8.5417), 460.0};

// --- Trajectory --------------------------------------------------------------------------------

/// Length of Zhao & Song's survey flown by skylane: `lines` lines of `len` joined by `lines − 1`
/// cross legs of `spacing`, every one of the 2(lines − 1) right-angle corners rounded by an arc of
/// radius r, which replaces two tangent lengths r·tan 45° of straight flight by r·π/2 of arc.
double surveyLength(int lines, double len, double spacing, double r) {
  const int corners = 2 * (lines - 1);
  return lines * len + (lines - 1) * spacing - corners * (2.0 * r - r * M_PI / 2.0);
}

TEST(SimTrajectory, SurveyDurationIsTheFilletedLengthOverTheSpeed) {
  const Trajectory t(kZurich, lawnmower(7, 1000.0, 100.0, 60.0, 10.0, 0.0), 30.0);
  const double expected = surveyLength(7, 1000.0, 100.0, 30.0) / 10.0;  // 744.549 s
  EXPECT_NEAR(t.duration_s(), expected, 1e-9);
  // The corners cut 12 × (60 − 15π) m = 154.5 m off the 7600 m polyline.
  EXPECT_NEAR(7600.0 / 10.0 - t.duration_s(), 12.0 * (60.0 - 15.0 * M_PI) / 10.0, 1e-9);
  // Start and end: first and last waypoint, 60 m up.
  EXPECT_TRUE(test::nearVec(t.at(0.0).p_enu_m, Eigen::Vector3d(0.0, 0.0, 60.0), 1e-9));
  EXPECT_TRUE(test::nearVec(t.at(t.duration_s()).p_enu_m, Eigen::Vector3d(600.0, 1000.0, 60.0), 1e-6));
}

// Zhao & Song's survey spans 0–750 s in their figures: the bundled example flies 7 lines of 1010 m,
// 100 m apart, at 10 m/s with 30 m turns, which lasts ≥ 750 s (7 lines of 1000 m: 744.5 s).
TEST(SimTrajectory, SurveyLastsAtLeastThePapersPlottedSpan) {
  const Trajectory t(kZurich, lawnmower(7, 1010.0, 100.0, 60.0, 10.0, 0.0), 30.0);
  EXPECT_GE(t.duration_s(), 750.0);
}

/// Central differences of position and velocity agree with the analytic velocity and acceleration
/// everywhere (position) and away from the curvature / slope joints (velocity).
void expectDerivativesConsistent(const Trajectory& t) {
  constexpr double kH = 1e-4;               // s: truncation ≤ Δa·h/4 at a joint, roundoff ≈ 1e-9
  constexpr double kVelTol_mps = 1e-3;      // brief: 1e-3 m/s
  constexpr double kAccTol_mps2 = 1e-3;
  constexpr double kJoint_mps2 = 1e-2;      // a(t ± h) differing by more than this: a joint inside
  int checked_acc = 0;
  for (double s = 2.0 * kH; s < t.duration_s() - 2.0 * kH; s += 0.0937) {
    const TruthState x = t.at(s), xp = t.at(s + kH), xm = t.at(s - kH);
    const Eigen::Vector3d v_num = (xp.p_enu_m - xm.p_enu_m) / (2.0 * kH);
    if (!test::nearVec(v_num, x.v_enu_mps, kVelTol_mps)) {
      ADD_FAILURE() << "velocity at t = " << s << ": " << test::nearVec(v_num, x.v_enu_mps, kVelTol_mps).message();
      return;
    }
    if ((xp.a_enu_mps2 - xm.a_enu_mps2).cwiseAbs().maxCoeff() > kJoint_mps2) continue;
    ++checked_acc;
    const Eigen::Vector3d a_num = (xp.v_enu_mps - xm.v_enu_mps) / (2.0 * kH);
    if (!test::nearVec(a_num, x.a_enu_mps2, kAccTol_mps2)) {
      ADD_FAILURE() << "acceleration at t = " << s << ": " << test::nearVec(a_num, x.a_enu_mps2, kAccTol_mps2).message();
      return;
    }
    // ECEF velocity is the same rotation of the ENU one (the origin frame is Cartesian).
    const Eigen::Vector3d v_ecef_num = (xp.p_ecef_m - xm.p_ecef_m) / (2.0 * kH);
    if (!test::nearVec(v_ecef_num, x.v_ecef_mps, 1e-3)) {
      ADD_FAILURE() << "ECEF velocity at t = " << s;
      return;
    }
  }
  EXPECT_GT(checked_acc, static_cast<int>(t.duration_s() / 0.0937) * 9 / 10);
}

TEST(SimTrajectory, VelocityAndAccelerationAreDerivativesOnTheSurvey) {
  expectDerivativesConsistent(Trajectory(kZurich, lawnmower(7, 1000.0, 100.0, 60.0, 10.0, 0.0), 30.0));
}

/// A climbing, turning path with speed changes (slope blends and speed ramps exercised).
std::vector<Waypoint> climbingPath() {
  return {{Eigen::Vector3d(0, 0, 0), 1.0},
          {Eigen::Vector3d(500, 0, 50), 10.0},
          {Eigen::Vector3d(500, 400, 50), 15.0},
          {Eigen::Vector3d(100, 300, 0), 8.0},
          {Eigen::Vector3d(-200, 600, 40), 12.0}};
}

TEST(SimTrajectory, VelocityAndAccelerationAreDerivativesWhileClimbingAndSpeedingUp) {
  expectDerivativesConsistent(Trajectory(kZurich, climbingPath(), 40.0));
}

TEST(SimTrajectory, AttitudeFollowsTheVelocityAndTheCoordinatedTurn) {
  const std::pair<const char*, Trajectory> paths[] = {
      {"survey", Trajectory(kZurich, lawnmower(3, 400.0, 100.0, 60.0, 10.0, 0.3), 30.0)},
      {"climbing", Trajectory(kZurich, climbingPath(), 30.0)}};
  for (const auto& [name, traj] : paths) {
    SCOPED_TRACE(name);
    int on_arc = 0;
    for (double s = 0.05; s < traj.duration_s(); s += 0.1) {
      const TruthState x = traj.at(s);
      // Local ENU at the vehicle, from the geodesy.
      const Eigen::Matrix3d R_enu_ecef = maps::rotationEcefToEnu(x.geodetic.lat_rad, x.geodetic.lon_rad);
      const Eigen::Vector3d v = R_enu_ecef * x.v_ecef_mps;
      ASSERT_NEAR(std::remainder(x.heading_rad - std::atan2(v.x(), v.y()), 2 * M_PI), 0.0, 1e-12) << s;
      ASSERT_NEAR(x.pitch_rad - std::atan2(v.z(), v.head<2>().norm()), 0.0, 1e-12) << s;
      // The origin's ENU differs from the local one by the meridian convergence Δλ·sin φ (≤ 1e-4
      // rad within 600 m of the origin at 47° N) and the climb's tilt of the frame.
      ASSERT_NEAR(std::remainder(x.heading_rad - std::atan2(x.v_enu_mps.x(), x.v_enu_mps.y()), 2 * M_PI), 0.0, 1.5e-4);
      // The body's forward axis points along the velocity.
      ASSERT_GT(x.C_ecef_body.col(0).dot(x.v_ecef_mps.normalized()), 1.0 - 1e-12) << s;
      ASSERT_LT((x.C_ecef_body - R_enu_ecef.transpose() * x.C_enu_body).cwiseAbs().maxCoeff(), 1e-12);
      // Bank of a coordinated turn, curvature from v and a: κ = (v × a)_z / |v_h|³ — once the
      // curvature has been the same for the 1 s the bank takes to roll in (±0.6 s here).
      auto curvature = [&traj = traj](double t) {
        const TruthState y = traj.at(t);
        const Eigen::Vector2d vh = y.v_enu_mps.head<2>(), ah = y.a_enu_mps2.head<2>();
        return (vh.x() * ah.y() - vh.y() * ah.x()) / std::pow(vh.norm(), 3);
      };
      const double speed_h = x.v_enu_mps.head<2>().norm();
      const double kappa = curvature(s);
      if (s > 0.6 && s + 0.6 < traj.duration_s() && std::abs(curvature(s - 0.6) - kappa) < 1e-9 &&
          std::abs(curvature(s + 0.6) - kappa) < 1e-9) {
        ASSERT_NEAR(x.roll_rad, -std::atan(kappa * speed_h * speed_h / kG_mps2), 1e-9) << s;
      }
      // The roll rate stays below tan(bank) of the fastest turn per second (the bank's tangent
      // ramps linearly over 1 s; the paths fly ≤ 15 m/s on 30 m arcs). A step would be ≥ 4 rad/s.
      if (s + 0.1 < traj.duration_s()) {
        ASSERT_LT(std::abs(traj.at(s + 0.1).roll_rad - x.roll_rad) / 0.1, 1.05 * 15.5 * 15.5 / (30.0 * kG_mps2)) << s;
      }
      if (std::abs(std::abs(kappa) - 1.0 / 30.0) < 1e-9) {
        ++on_arc;
        // Right turn (κ < 0): right wing down, roll > 0.
        ASSERT_EQ(x.roll_rad > 0.0, kappa < 0.0) << s;
      }
    }
    EXPECT_GT(on_arc, 10);
  }
  // The survey's first corner (north → east) is a right turn at 10 m/s on 30 m: roll = atan(100/(30 g)).
  const Trajectory survey(kZurich, lawnmower(2, 400.0, 100.0, 60.0, 10.0, 0.0), 30.0);
  const double t_mid_corner = (400.0 - 30.0 + 30.0 * M_PI / 4.0) / 10.0;
  const TruthState x = survey.at(t_mid_corner);
  EXPECT_NEAR(x.roll_rad, std::atan(100.0 / (30.0 * kG_mps2)), 1e-9);
  EXPECT_NEAR(x.heading_rad, M_PI / 4.0, 1e-3);  // half-way round: north-east (± meridian convergence)
}

TEST(SimTrajectory, BodyToEnuIsHeadingPitchRoll) {
  // Heading 90° (east), pitch 10°, roll 0: forward = east tilted up, left = north.
  const Eigen::Matrix3d C = bodyToEnu(M_PI / 2, maps::deg2rad(10.0), 0.0);
  EXPECT_TRUE(test::nearVec(C.col(0), Eigen::Vector3d(std::cos(maps::deg2rad(10.0)), 0, std::sin(maps::deg2rad(10.0))), 1e-15));
  EXPECT_TRUE(test::nearVec(C.col(1), Eigen::Vector3d(0, 1, 0), 1e-15));
  // Heading 0 (north), roll 20° right wing down: the left axis (west) rises.
  const Eigen::Matrix3d D = bodyToEnu(0.0, 0.0, maps::deg2rad(20.0));
  EXPECT_TRUE(test::nearVec(D.col(0), Eigen::Vector3d(0, 1, 0), 1e-15));
  EXPECT_TRUE(test::nearVec(D.col(1), Eigen::Vector3d(-std::cos(maps::deg2rad(20.0)), 0, std::sin(maps::deg2rad(20.0))), 1e-15));
}

TEST(SimTrajectory, InvalidInputsThrowNamingTheProblem) {
  struct Case {
    const char* name;
    std::vector<Waypoint> wps;
    double radius;
    const char* expect;
  };
  const Case cases[] = {
      {"one waypoint", {{Eigen::Vector3d(0, 0, 0), 10.0}}, 30.0, "at least two waypoints"},
      {"zero speed", {{Eigen::Vector3d(0, 0, 0), 10.0}, {Eigen::Vector3d(100, 0, 0), 0.0}}, 30.0, "speed"},
      {"180° reversal",
       {{Eigen::Vector3d(0, 0, 0), 10.0}, {Eigen::Vector3d(100, 0, 0), 10.0}, {Eigen::Vector3d(0, 0, 0), 10.0}},
       30.0,
       "170°"},
      {"climb > 60°", {{Eigen::Vector3d(0, 0, 0), 10.0}, {Eigen::Vector3d(10, 0, 20), 10.0}}, 30.0, "60°"},
      {"repeated waypoint", {{Eigen::Vector3d(0, 0, 0), 10.0}, {Eigen::Vector3d(0, 0, 5), 10.0}}, 30.0, "1 mm"},
      {"zero radius", {{Eigen::Vector3d(0, 0, 0), 10.0}, {Eigen::Vector3d(100, 0, 0), 10.0}}, 0.0, "radius"},
  };
  for (const Case& c : cases) {
    const std::string msg = test::messageOf<std::invalid_argument>([&] { (void)Trajectory(kZurich, c.wps, c.radius); });
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.name << ": " << msg;
  }
  // A 59° climb is flyable.
  EXPECT_NO_THROW((void)Trajectory(
      kZurich, {{Eigen::Vector3d(0, 0, 0), 10.0}, {Eigen::Vector3d(10, 0, 10 * std::tan(maps::deg2rad(59.0))), 10.0}}, 30.0));
  EXPECT_THROW((void)lawnmower(0, 1000.0, 100.0, 60.0, 10.0, 0.0), std::invalid_argument);
  EXPECT_THROW((void)lawnmower(3, 1000.0, 100.0, 60.0, 0.0, 0.0), std::invalid_argument);
}

// --- Sensors --------------------------------------------------------------------------------------

TEST(SimFaultSpec, StepHoldsInsideTheWindowAndRampGrows) {
  FaultSpec step;
  step.t_start_s = 200.0;
  step.t_end_s = 250.0;
  step.magnitude = 3.5;
  EXPECT_EQ(step.valueAt(199.999), 0.0);
  EXPECT_EQ(step.valueAt(200.0), 3.5);  // [start, end)
  EXPECT_EQ(step.valueAt(230.0), 3.5);
  EXPECT_EQ(step.valueAt(249.999), 3.5);
  EXPECT_EQ(step.valueAt(250.0), 0.0);
  EXPECT_EQ(step.valueAt(1e6), 0.0);

  FaultSpec ramp = step;
  ramp.ramp = true;
  ramp.magnitude = 0.5;  // per second
  EXPECT_EQ(ramp.valueAt(199.0), 0.0);
  EXPECT_DOUBLE_EQ(ramp.valueAt(200.0), 0.0);
  EXPECT_DOUBLE_EQ(ramp.valueAt(204.0), 2.0);
  EXPECT_DOUBLE_EQ(ramp.valueAt(249.0), 24.5);
  EXPECT_EQ(ramp.valueAt(250.0), 0.0);
  // Linear: equal steps in time, equal steps in value.
  EXPECT_NEAR(ramp.valueAt(230.0) - ramp.valueAt(220.0), ramp.valueAt(220.0) - ramp.valueAt(210.0), 1e-12);
}

TEST(SimImuSpec, TurnOnBiasesAreTheImuGradeTable) {
  const ImuSpec av = imuSpec(ImuGrade::kAviation);
  EXPECT_DOUBLE_EQ(av.accel_bias_mps2, 3e-4);
  EXPECT_DOUBLE_EQ(av.gyro_bias_radps, 5e-8);
  const ImuSpec ta = imuSpec(ImuGrade::kTactical);
  EXPECT_DOUBLE_EQ(ta.accel_bias_mps2, 1e-2);
  EXPECT_DOUBLE_EQ(ta.gyro_bias_radps, 5e-6);
  const ImuSpec co = imuSpec(ImuGrade::kConsumer);
  EXPECT_DOUBLE_EQ(co.accel_bias_mps2, 3e-2);
  // Grades are ordered: every error figure grows from aviation to consumer.
  for (auto f : {&ImuSpec::accel_bias_mps2, &ImuSpec::gyro_bias_radps, &ImuSpec::accel_noise_mps_rts,
                 &ImuSpec::gyro_noise_rad_rts, &ImuSpec::accel_bias_rw_mps2_rts, &ImuSpec::gyro_bias_rw_radps_rts}) {
    EXPECT_LT(av.*f, ta.*f);
    EXPECT_LT(ta.*f, co.*f);
  }
  for (ImuGrade g : {ImuGrade::kAviation, ImuGrade::kTactical, ImuGrade::kConsumer}) {
    const auto back = parseImuGrade(imuGradeName(g));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, g);
  }
  EXPECT_FALSE(parseImuGrade("navigation").has_value());
}

// --- Run statistics ---------------------------------------------------------------------------------

TEST(SimUpperBound95, MatchesClopperPearson) {
  // k = 0: 1 − 0.05^(1/n), the exact bound behind the rule of three.
  for (std::uint64_t n : {10u, 100u, 1000u, 100000u}) {
    const double dn = static_cast<double>(n);
    EXPECT_NEAR(upperBound95(0, n), 1.0 - std::pow(0.05, 1.0 / dn), 1e-15) << n;
    EXPECT_NEAR(upperBound95(0, n), 3.0 / dn, 0.16 * 3.0 / dn) << n;
  }
  EXPECT_NEAR(upperBound95(1, 100), 0.0466, 0.5e-4);   // Clopper–Pearson, 3 significant digits
  EXPECT_NEAR(upperBound95(5, 1000), 0.0105, 1e-4);
  // Independent: (1 − p)^n + n p (1 − p)^(n − 1) = 0.05 at the bound for k = 1.
  const double p = upperBound95(1, 100);
  EXPECT_NEAR(std::pow(1.0 - p, 100) + 100.0 * p * std::pow(1.0 - p, 99), 0.05, 1e-9);
  EXPECT_EQ(upperBound95(3, 0), 1.0);
  EXPECT_EQ(upperBound95(10, 10), 1.0);
  // Monotone in k.
  double prev = 0.0;
  for (std::uint64_t k = 0; k < 30; ++k) {
    const double b = upperBound95(k, 200);
    EXPECT_GT(b, prev) << k;
    EXPECT_GT(b, static_cast<double>(k) / 200.0) << k;
    prev = b;
  }
}

struct StanfordCase {
  const char* name;
  double error_m, pl_m;
  bool available;
  // expected counters: normal, mi, hmi, unavailable, unavailable_mi, no_pl, misleading
  std::array<int, 7> counts;
};

TEST(SimStanfordHistogram, ClassifiesEveryRegionAndItsBoundaries) {
  constexpr double kAl = 40.0;
  const StanfordCase cases[] = {
      {"normal", 10.0, 20.0, true, {1, 0, 0, 0, 0, 0, 0}},
      {"error == PL is bounded", 20.0, 20.0, true, {1, 0, 0, 0, 0, 0, 0}},
      {"MI", 25.0, 20.0, true, {0, 1, 0, 0, 0, 0, 1}},
      {"MI with error == AL", 40.0, 30.0, true, {0, 1, 0, 0, 0, 0, 1}},
      {"HMI", 45.0, 30.0, true, {0, 0, 1, 0, 0, 0, 1}},
      {"PL == AL is available", 30.0, 40.0, true, {1, 0, 0, 0, 0, 0, 0}},
      {"PL == AL, error == AL", 40.0, 40.0, true, {1, 0, 0, 0, 0, 0, 0}},
      {"PL == AL, error > AL: HMI", 50.0, 40.0, true, {0, 0, 1, 0, 0, 0, 1}},
      {"unavailable", 10.0, 45.0, true, {0, 0, 0, 1, 0, 0, 0}},
      {"unavailable, error == PL", 45.0, 45.0, true, {0, 0, 0, 1, 0, 0, 0}},
      {"unavailable MI", 50.0, 45.0, true, {0, 0, 0, 1, 1, 0, 1}},
      {"no PL", 100.0, 0.0, false, {0, 0, 0, 0, 0, 1, 0}},
  };
  StanfordHistogram all(kAl, 80.0, 100);
  for (const StanfordCase& c : cases) {
    StanfordHistogram h(kAl, 80.0, 100);
    h.add(c.error_m, c.pl_m, c.available);
    all.add(c.error_m, c.pl_m, c.available);
    const std::array<std::uint64_t, 7> got{h.normal, h.mi, h.hmi, h.unavailable, h.unavailable_mi, h.no_pl, h.misleading};
    for (int i = 0; i < 7; ++i) {
      EXPECT_EQ(got[i], static_cast<std::uint64_t>(c.counts[i])) << c.name << ", counter " << i;
    }
    EXPECT_EQ(h.total, 1u) << c.name;
    std::uint64_t binned = 0;
    for (std::uint64_t v : h.counts) binned += v;
    EXPECT_EQ(binned, c.available ? 1u : 0u) << c.name;
  }
  // Totals add up; the regions partition the available epochs.
  EXPECT_EQ(all.total, 12u);
  EXPECT_EQ(all.normal + all.mi + all.hmi + all.unavailable + all.no_pl, all.total);
  EXPECT_EQ(all.misleading, 5u);
  // Bins: row = PL bin, column = error bin, width 0.8 m; beyond max clamps into the last bin.
  StanfordHistogram b(kAl, 80.0, 100);
  b.add(10.0, 20.0, true);   // error bin 12, PL bin 25
  b.add(500.0, 90.0, true);  // both clamp to 99
  EXPECT_EQ(b.counts[25 * 100 + 12], 1u);
  EXPECT_EQ(b.counts[99 * 100 + 99], 1u);
  // Merge adds counts and counters; a different shape is refused.
  StanfordHistogram m = b;
  m.merge(all);
  EXPECT_EQ(m.total, 14u);
  EXPECT_EQ(m.misleading, all.misleading + b.misleading);
  EXPECT_EQ(m.counts[25 * 100 + 12], 1u + all.counts[25 * 100 + 12]);
  EXPECT_THROW(m.merge(StanfordHistogram(kAl, 80.0, 50)), std::invalid_argument);
}

// --- Scenario --------------------------------------------------------------------------------------

nlohmann::json validScenario() {
  return nlohmann::json::parse(R"({
    "origin": {"lat_deg": 47.3769, "lon_deg": 8.5417, "h_ell_m": 460.0},
    "start": "2020-01-01T10:00:00Z",
    "orbits": ["data/alm.txt"],
    "trajectory": {
      "lawnmower": {"lines": 7, "line_length_m": 1000, "spacing_m": 100, "height_m": 60, "speed_mps": 10, "heading_deg": 0},
      "turn_radius_m": 30
    },
    "imu": {"grade": "tactical", "rate_hz": 100},
    "gnss": {"rate_hz": 1, "elevation_mask_deg": 5, "user_model": "dual_frequency"},
    "baro": true,
    "magnetometer": false,
    "faults": [
      {"type": "satellite", "sats": ["G19"], "start_s": 200, "end_s": 250, "bias_sigma": 10},
      {"type": "accelerometer", "axis": "up", "start_s": 200, "end_s": 250, "bias_g": 20e-4},
      {"type": "gyro", "axis": "forward", "start_s": 100, "end_s": 110, "ramp": true, "bias_dps": 0.5},
      {"type": "outage", "start_s": 300, "end_s": 320}
    ],
    "integrity": {"hal_m": 35, "val_m": 45, "i_req": 1e-7, "p_sat": 1e-5, "p_imu": 1e-3},
    "seed": 42
  })");
}

TEST(SimScenario, ValidLawnmowerScenarioParses) {
  const Scenario s = parseScenario(validScenario(), "test.json", ".");
  EXPECT_EQ(s.source, "test.json");
  EXPECT_NEAR(s.origin.lat_rad, maps::deg2rad(47.3769), 1e-15);
  EXPECT_DOUBLE_EQ(s.origin.h_ell_m, 460.0);
  ASSERT_EQ(s.orbit_files.size(), 1u);
  EXPECT_EQ(s.orbit_files[0], "data/alm.txt");
  EXPECT_EQ(s.waypoints.size(), 14u);
  EXPECT_DOUBLE_EQ(s.turn_radius_m, 30.0);
  EXPECT_EQ(s.grade, ImuGrade::kTactical);
  EXPECT_DOUBLE_EQ(s.hal_m, 35.0);
  EXPECT_DOUBLE_EQ(s.val_m, 45.0);
  EXPECT_EQ(s.seed, 42u);
  EXPECT_TRUE(s.navigator.use_baro);
  EXPECT_FALSE(s.navigator.use_heading);
  EXPECT_DOUBLE_EQ(s.navigator.araim.requirements.hal_m, 35.0);
  EXPECT_DOUBLE_EQ(s.navigator.araim.requirements.val_m, 45.0);

  ASSERT_EQ(s.faults.size(), 4u);
  const FaultSpec& sat = s.faults[0];
  EXPECT_EQ(sat.target, FaultTarget::kSatellite);
  ASSERT_EQ(sat.sats.size(), 1u);
  EXPECT_EQ(sat.sats[0], *parseSatId("G19"));
  EXPECT_TRUE(sat.in_sigma);
  EXPECT_DOUBLE_EQ(sat.magnitude, 10.0);
  EXPECT_DOUBLE_EQ(sat.t_start_s, 200.0);
  EXPECT_DOUBLE_EQ(sat.t_end_s, 250.0);
  const FaultSpec& acc = s.faults[1];
  EXPECT_EQ(acc.target, FaultTarget::kAccelerometer);
  EXPECT_EQ(acc.axis, 2);
  EXPECT_NEAR(acc.magnitude, 20e-4 * kG_mps2, 1e-15);  // Zhao & Song 2024: 20 × 10⁻⁴ g
  const FaultSpec& gyro = s.faults[2];
  EXPECT_EQ(gyro.target, FaultTarget::kGyro);
  EXPECT_EQ(gyro.axis, 0);
  EXPECT_TRUE(gyro.ramp);
  EXPECT_NEAR(gyro.magnitude, 0.5 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(s.faults[3].target, FaultTarget::kGnssOutage);
  EXPECT_EQ(s.faults[3].valueAt(310.0), 1.0);

  // The filter assumes the simulated IMU's figures (matchFilterToSensors).
  const ImuSpec tac = imuSpec(ImuGrade::kTactical);
  const ins::EkfConfig& e = s.navigator.ekf;
  EXPECT_EQ(e.accel_bias_mps2, tac.accel_bias_mps2);
  EXPECT_EQ(e.gyro_bias_radps, tac.gyro_bias_radps);
  EXPECT_EQ(e.accel_noise_mps_rts, tac.accel_noise_mps_rts);
  EXPECT_EQ(e.gyro_noise_rad_rts, tac.gyro_noise_rad_rts);
  EXPECT_EQ(e.accel_bias_rw_mps2_rts, tac.accel_bias_rw_mps2_rts);
  EXPECT_EQ(e.gyro_bias_rw_radps_rts, tac.gyro_bias_rw_radps_rts);
  EXPECT_EQ(s.sensors.imu.accel_bias_mps2, 1e-2);
  EXPECT_EQ(e.baro_noise_m, s.sensors.baro_noise_m);
  EXPECT_EQ(e.heading_noise_rad, s.sensors.heading_noise_rad);
  EXPECT_DOUBLE_EQ(s.navigator.three_hypothesis_ins.lambda, 5.0 / 12.0);  // US 10,466,362: tactical λ
  EXPECT_DOUBLE_EQ(s.navigator.three_hypothesis_ins.phmi_h, 5e-8);
  EXPECT_DOUBLE_EQ(s.navigator.three_hypothesis_ins.phmi_v, 5e-8);
  EXPECT_NEAR(s.navigator.elevation_mask_rad, maps::deg2rad(5.0), 1e-15);

  // The same scenario with the consumer grade: the filter follows.
  nlohmann::json consumer = validScenario();
  consumer["imu"]["grade"] = "consumer";
  const Scenario c = parseScenario(consumer, "test.json", ".");
  EXPECT_EQ(c.navigator.ekf.accel_bias_mps2, 3e-2);
  EXPECT_DOUBLE_EQ(c.navigator.three_hypothesis_ins.lambda, 9.0 / 12.0);
}

TEST(SimScenario, ErrorsNameTheFieldAndWhatWasExpected) {
  struct Case {
    const char* name;
    std::function<void(nlohmann::json&)> edit;
    std::vector<std::string> expect;  // every one must appear in the message
  };
  const std::vector<Case> cases = {
      {"unknown top-level field", [](nlohmann::json& j) { j["wingspan_m"] = 3; }, {"wingspan_m", "test.json"}},
      {"unknown fault type", [](nlohmann::json& j) { j["faults"][0]["type"] = "meteor"; },
       {"meteor", "satellite", "faults[0].type"}},
      {"bad satellite id", [](nlohmann::json& j) { j["faults"][0]["sats"] = nlohmann::json::array({"X99"}); },
       {"X99", "G19", "faults[0].sats[0]"}},
      {"end before start", [](nlohmann::json& j) { j["faults"][1]["end_s"] = 200; }, {"end_s", "start_s"}},
      {"bad grade", [](nlohmann::json& j) { j["imu"]["grade"] = "military"; }, {"military", "consumer"}},
      {"latitude", [](nlohmann::json& j) { j["origin"]["lat_deg"] = 90; }, {"lat_deg"}},
      {"probability", [](nlohmann::json& j) { j["integrity"]["p_sat"] = 1.5; }, {"p_sat", "probability"}},
      {"both trajectories", [](nlohmann::json& j) { j["trajectory"]["waypoints"] = nlohmann::json::array(); }, {"lawnmower"}},
      {"zero lines", [](nlohmann::json& j) { j["trajectory"]["lawnmower"]["lines"] = 0; }, {"lawnmower.lines", "1…1000"}},
      // Bounds (issue 23 item 9): each number that feeds a loop, the frame or the clock.
      {"IMU rate 1e9", [](nlohmann::json& j) { j["imu"]["rate_hz"] = 1e9; }, {"test.json", "$.imu.rate_hz", "1000000000", "≤ 2000 Hz"}},
      {"IMU samples", [](nlohmann::json& j) { j["imu"]["rate_hz"] = 2000; j["trajectory"]["lawnmower"]["lines"] = 100; },
       {"$.imu.rate_hz", "at most 2e+07 IMU samples"}},
      {"IMU rate not a multiple", [](nlohmann::json& j) { j["gnss"]["rate_hz"] = 3; }, {"$.imu.rate_hz", "whole multiple of the GNSS rate (3 Hz)"}},
      {"GNSS rate", [](nlohmann::json& j) { j["gnss"]["rate_hz"] = 1e6; }, {"$.gnss.rate_hz", "≤ 20 Hz"}},
      {"spacing 1e99", [](nlohmann::json& j) { j["trajectory"]["lawnmower"]["spacing_m"] = 1e99; },
       {"lawnmower.spacing_m", "1e+99", "lines × spacing within 100 km"}},
      {"line length", [](nlohmann::json& j) { j["trajectory"]["lawnmower"]["line_length_m"] = 1e12; }, {"line_length_m", "≤ 100000 m"}},
      {"slow flight", [](nlohmann::json& j) { j["trajectory"]["lawnmower"]["speed_mps"] = 1e-3; },
       {"$.trajectory", "a flight of at most 86400 s"}},
      {"height", [](nlohmann::json& j) { j["origin"]["h_ell_m"] = 1e308; }, {"origin.h_ell_m", "[-1000, 20000] m"}},
      {"fault end", [](nlohmann::json& j) { j["faults"][1]["end_s"] = 1e99; }, {"faults[1].end_s", "[0, 86400] s"}},
      {"fault bias", [](nlohmann::json& j) { j["faults"][0]["bias_sigma"] = 1e308; }, {"faults[0].bias_sigma", "sigma"}},
      {"unflyable reversal",
       [](nlohmann::json& j) {
         j["trajectory"].erase("lawnmower");
         j["trajectory"]["waypoints"] = nlohmann::json::parse(
             R"([{"e_m": 0, "n_m": 0, "u_m": 0}, {"e_m": 100, "n_m": 0, "u_m": 0, "speed_mps": 10},
                 {"e_m": 0, "n_m": 0, "u_m": 0, "speed_mps": 10}])");
       },
       {"trajectory", "flyable", "170°"}},
  };
  for (const Case& c : cases) {
    nlohmann::json doc = validScenario();
    c.edit(doc);
    const std::string msg = test::messageOf<maps::ParseError>([&] { (void)parseScenario(doc, "test.json", "."); });
    ASSERT_FALSE(msg.empty()) << c.name << ": no ParseError";
    for (const std::string& part : c.expect) {
      EXPECT_NE(msg.find(part), std::string::npos) << c.name << ": '" << part << "' not in: " << msg;
    }
  }
}

}  // namespace
}  // namespace skylane::integrity::sim
