#pragma once
/// \file
/// \brief Truth trajectories for the GNSS/INS simulation: a polyline of waypoints flown at set
/// ground speeds, corners rounded into circular arcs, with attitude from the velocity (heading,
/// flight-path angle) and a coordinated-turn bank angle; and the survey ("lawnmower") of Zhao & Song 2024's simulation
/// pattern.
///
/// Frames: positions are in the local ENU frame of the trajectory's origin (a Cartesian frame:
/// its ECEF image is an affine map, so ECEF velocity and acceleration are the same rotation of
/// the ENU ones). The body frame is forward-left-up (FLU); attitude is given against the local
/// ENU frame *at the vehicle* (so a magnetometer or a level sensor sees what it would).

#include "integrity/ins/strapdown.hpp"
#include "maps/geodesy.hpp"

#include <Eigen/Core>

#include <vector>

namespace skylane::integrity::sim {

/// \brief A waypoint in the origin's ENU frame and the ground speed of the leg that ends there.
struct Waypoint {
  Eigen::Vector3d p_enu_m = Eigen::Vector3d::Zero();
  double speed_mps = 10.0;  ///< speed along the leg *into* this waypoint (the first one's is unused)
};

/// \brief The true kinematic state at one instant.
struct TruthState {
  double t_s = 0.0;
  Eigen::Vector3d p_enu_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_enu_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_enu_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_ecef_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ecef_mps = Eigen::Vector3d::Zero();
  maps::Geodetic geodetic;
  double heading_rad = 0.0;  ///< clockwise from north
  double pitch_rad = 0.0;    ///< nose up positive (flight-path angle)
  double roll_rad = 0.0;     ///< right wing down positive (coordinated-turn bank, rolled in over 1 s)
  Eigen::Matrix3d C_enu_body = Eigen::Matrix3d::Identity();   ///< body (FLU) → local ENU at the vehicle
  Eigen::Matrix3d C_ecef_body = Eigen::Matrix3d::Identity();  ///< body (FLU) → ECEF
};

using ins::bodyToEnu;

/// \brief A flyable path through waypoints.
class Trajectory {
 public:
  /// \brief Builds the path. Corners are rounded with the largest arc (up to `turn_radius_m`)
  /// that fits half of each adjacent leg; the speed changes linearly along each leg.
  /// \throws std::invalid_argument for fewer than two waypoints, a non-positive speed or radius,
  /// repeated waypoints, or a leg steeper than 60°.
  Trajectory(const maps::Geodetic& origin, std::vector<Waypoint> waypoints, double turn_radius_m);

  /// \brief Flight time from the first to the last waypoint [s].
  [[nodiscard]] double duration_s() const { return duration_s_; }
  /// \brief The truth at time t ∈ [0, duration] (clamped).
  [[nodiscard]] TruthState at(double t_s) const;
  /// \brief The origin's local frame.
  [[nodiscard]] const maps::LocalFrame& frame() const { return frame_; }
  /// \brief The origin's ENU → ECEF rotation.
  [[nodiscard]] const Eigen::Matrix3d& rotationEnuToEcef() const { return R_ecef_enu_; }

 private:
  /// One piece of the horizontal path: a straight line or a circular arc, with its vertical
  /// profile linear in arc length.
  struct Piece {
    bool arc = false;
    double s0 = 0.0, length = 0.0;    // start arc length and length [m] (horizontal)
    Eigen::Vector2d start = Eigen::Vector2d::Zero();
    Eigen::Vector2d dir = Eigen::Vector2d::Zero();     // line: unit direction
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // arc: centre
    double radius = 0.0, phase0 = 0.0, turn = 0.0;     // arc: signed sweep (+ counter-clockwise)
  };
  struct Leg {  // waypoint i → i+1 in horizontal arc length, with speed ramp and climb
    double s0 = 0.0, s1 = 0.0, h0 = 0.0, h1 = 0.0, v0 = 0.0, v1 = 0.0, t0 = 0.0, t1 = 0.0;
  };
  struct Corners;  // the constructor's horizontal plan: legs and corner arcs (trajectory.cpp)

  /// The constructor's steps: the horizontal legs and the arc that rounds each corner; the
  /// lines and arcs laid along them (returns each waypoint's station, its arc length); the legs
  /// between stations with their climb, speed ramp and times (returns the duration).
  [[nodiscard]] static Corners roundCorners(const std::vector<Waypoint>& waypoints, double turn_radius_m);
  [[nodiscard]] std::vector<double> layPieces(const Corners& corners);
  [[nodiscard]] double layLegs(const std::vector<Waypoint>& waypoints, const std::vector<double>& station_s);

  void horizontal(double s, Eigen::Vector2d& p, Eigen::Vector2d& tangent, double& curvature) const;
  /// The mean signed curvature over horizontal arc lengths [a, b] (clipped to the path; `at_s`
  /// when that leaves nothing).
  [[nodiscard]] double meanCurvature(double a, double b, double at_s) const;
  [[nodiscard]] double arcLengthAt(double t_s, double& speed, double& accel, const Leg*& leg) const;

  maps::LocalFrame frame_;
  Eigen::Matrix3d R_ecef_enu_;
  Eigen::Vector3d p_origin_ecef_;
  std::vector<Piece> pieces_;
  std::vector<Leg> legs_;
  double duration_s_ = 0.0;
};

/// \brief The survey pattern of Zhao & Song 2024: `lines` parallel lines of length `line_length_m`, spaced
/// `spacing_m`, flown back and forth at `height_m` above the origin and `speed_mps`, starting at
/// the origin heading along `heading_rad`.
[[nodiscard]] std::vector<Waypoint> lawnmower(int lines, double line_length_m, double spacing_m, double height_m,
                                              double speed_mps, double heading_rad);

}  // namespace skylane::integrity::sim
