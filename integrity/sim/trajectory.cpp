#include "integrity/sim/trajectory.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace skylane::integrity::sim {

namespace {

constexpr double kMaxCornerTurn_rad = 170.0 * M_PI / 180.0;
constexpr double kMaxSlope = 1.7320508075688772;  // tan 60°
constexpr double kStandardGravity_mps2 = 9.80665;

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// \brief At least two waypoints, a positive turn radius, a positive finite speed into each.
void requireFlyable(const std::vector<Waypoint>& waypoints, double turn_radius_m) {
  const std::size_t n = waypoints.size();
  if (n < 2) throw std::invalid_argument("trajectory: at least two waypoints are needed, got " + std::to_string(n));
  if (!(turn_radius_m > 0.0)) throw std::invalid_argument("trajectory: turn radius must be > 0 m");
  for (std::size_t i = 1; i < n; ++i) {
    if (!(waypoints[i].speed_mps > 0.0) || !std::isfinite(waypoints[i].speed_mps)) {
      throw std::invalid_argument("trajectory: waypoint " + std::to_string(i) + ": speed must be > 0 m/s");
    }
  }
}

}  // namespace

/// The waypoints' horizontal positions, each leg's length and direction, and each corner's
/// signed turn, arc radius and tangent distance (0 at the ends and where the path runs straight).
struct Trajectory::Corners {
  std::vector<Eigen::Vector2d> p;
  std::vector<double> leg_len;
  std::vector<Eigen::Vector2d> leg_dir;
  std::vector<double> tangent_dist;  // corner i: distance from the waypoint to the arc's ends
  std::vector<double> radius, turn;
};

Trajectory::Trajectory(const maps::Geodetic& origin, std::vector<Waypoint> waypoints, double turn_radius_m)
    : frame_(origin) {
  requireFlyable(waypoints, turn_radius_m);
  R_ecef_enu_ = maps::rotationEcefToEnu(origin.lat_rad, origin.lon_rad).transpose();
  p_origin_ecef_ = maps::geodeticToEcef(origin);

  // Horizontal legs and corner arcs.
  const Corners corners = roundCorners(waypoints, turn_radius_m);
  const std::vector<double> station_s = layPieces(corners);

  // Vertical profile and speed per leg (between stations).
  duration_s_ = layLegs(waypoints, station_s);
}

Trajectory::Corners Trajectory::roundCorners(const std::vector<Waypoint>& waypoints, double turn_radius_m) {
  const std::size_t n = waypoints.size();
  Corners corners;
  corners.p.resize(n);
  corners.leg_len.resize(n - 1);
  corners.leg_dir.resize(n - 1);
  corners.tangent_dist.assign(n, 0.0);
  corners.radius.assign(n, 0.0);
  corners.turn.assign(n, 0.0);
  std::vector<Eigen::Vector2d>& p = corners.p;
  std::vector<double>& leg_len = corners.leg_len;
  std::vector<Eigen::Vector2d>& leg_dir = corners.leg_dir;
  std::vector<double>& tangent_dist = corners.tangent_dist;
  std::vector<double>& radius = corners.radius;
  std::vector<double>& turn = corners.turn;
  for (std::size_t i = 0; i < n; ++i) p[i] = waypoints[i].p_enu_m.head<2>();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    leg_len[i] = (p[i + 1] - p[i]).norm();
    if (leg_len[i] < 1e-3) {
      throw std::invalid_argument("trajectory: waypoints " + std::to_string(i) + " and " + std::to_string(i + 1) +
                                  " are less than 1 mm apart horizontally");
    }
    leg_dir[i] = (p[i + 1] - p[i]) / leg_len[i];
  }
  for (std::size_t i = 1; i + 1 < n; ++i) {
    turn[i] = std::atan2(cross2(leg_dir[i - 1], leg_dir[i]), leg_dir[i - 1].dot(leg_dir[i]));
    if (std::abs(turn[i]) > kMaxCornerTurn_rad) {
      throw std::invalid_argument("trajectory: the corner at waypoint " + std::to_string(i) +
                                  " turns by more than 170°; add a waypoint to fly the reversal");
    }
    if (std::abs(turn[i]) < 1e-9) continue;
    const double half_tan = std::tan(std::abs(turn[i]) / 2.0);
    radius[i] = std::min(turn_radius_m, 0.5 * std::min(leg_len[i - 1], leg_len[i]) / half_tan);
    tangent_dist[i] = radius[i] * half_tan;
  }
  return corners;
}

std::vector<double> Trajectory::layPieces(const Corners& corners) {
  const std::vector<Eigen::Vector2d>& p = corners.p;
  const std::vector<double>& leg_len = corners.leg_len;
  const std::vector<Eigen::Vector2d>& leg_dir = corners.leg_dir;
  const std::vector<double>& tangent_dist = corners.tangent_dist;
  const std::vector<double>& radius = corners.radius;
  const std::vector<double>& turn = corners.turn;
  const std::size_t n = p.size();
  std::vector<double> station_s(n, 0.0);  // arc length at each waypoint's station
  double s = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Eigen::Vector2d a = p[i] + leg_dir[i] * tangent_dist[i];
    const double line_len = leg_len[i] - tangent_dist[i] - tangent_dist[i + 1];
    if (line_len > 0.0) {
      Piece line;
      line.s0 = s;
      line.length = line_len;
      line.start = a;
      line.dir = leg_dir[i];
      pieces_.push_back(line);
      s += line_len;
    }
    if (i + 1 < n - 1 && radius[i + 1] > 0.0) {
      const std::size_t c = i + 1;
      Piece arc;
      arc.arc = true;
      arc.s0 = s;
      arc.radius = radius[c];
      arc.turn = turn[c];
      arc.length = radius[c] * std::abs(turn[c]);
      arc.start = p[c] - leg_dir[i] * tangent_dist[c];
      const double side = turn[c] > 0.0 ? 1.0 : -1.0;  // centre to the left for a left turn
      const Eigen::Vector2d normal(-leg_dir[i].y() * side, leg_dir[i].x() * side);
      arc.centre = arc.start + normal * radius[c];
      const Eigen::Vector2d r0 = arc.start - arc.centre;
      arc.phase0 = std::atan2(r0.y(), r0.x());
      station_s[c] = s + arc.length / 2.0;
      pieces_.push_back(arc);
      s += arc.length;
    } else if (i + 1 < n - 1) {
      station_s[i + 1] = s;
    }
  }
  station_s[n - 1] = s;
  return station_s;
}

double Trajectory::layLegs(const std::vector<Waypoint>& waypoints, const std::vector<double>& station_s) {
  const std::size_t n = waypoints.size();
  legs_.resize(n - 1);
  double t = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    Leg& leg = legs_[i];
    leg.s0 = station_s[i];
    leg.s1 = station_s[i + 1];
    leg.h0 = waypoints[i].p_enu_m.z();
    leg.h1 = waypoints[i + 1].p_enu_m.z();
    if (std::abs(leg.h1 - leg.h0) > kMaxSlope * (leg.s1 - leg.s0)) {
      throw std::invalid_argument("trajectory: leg " + std::to_string(i) + " → " + std::to_string(i + 1) +
                                  " climbs or descends steeper than 60°");
    }
    const double v_in = waypoints[i + 1].speed_mps;
    leg.v0 = i == 0 ? v_in : 0.5 * (waypoints[i].speed_mps + v_in);
    leg.v1 = i + 2 == n ? v_in : 0.5 * (v_in + waypoints[i + 2].speed_mps);
    leg.t0 = t;
    const double len = leg.s1 - leg.s0;
    const double k = (leg.v1 - leg.v0) / len;  // dv/ds
    t += std::abs(k) < 1e-12 ? len / leg.v0 : std::log(leg.v1 / leg.v0) / k;
    leg.t1 = t;
  }
  return t;
}

void Trajectory::horizontal(double s, Eigen::Vector2d& p, Eigen::Vector2d& tangent, double& curvature) const {
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s, [](double v, const Piece& pc) { return v < pc.s0; });
  const Piece& pc = it == pieces_.begin() ? pieces_.front() : *(it - 1);
  const double u = std::clamp(s - pc.s0, 0.0, pc.length);
  if (!pc.arc) {
    p = pc.start + pc.dir * u;
    tangent = pc.dir;
    curvature = 0.0;
    return;
  }
  const double side = pc.turn > 0.0 ? 1.0 : -1.0;
  const double phase = pc.phase0 + side * u / pc.radius;
  const Eigen::Vector2d radial(std::cos(phase), std::sin(phase));
  p = pc.centre + radial * pc.radius;
  tangent = Eigen::Vector2d(-radial.y(), radial.x()) * side;
  curvature = side / pc.radius;  // signed, + = turning left
}

double Trajectory::arcLengthAt(double t_s, double& speed, double& accel, const Leg*& leg) const {
  const double t = std::clamp(t_s, 0.0, duration_s_);
  auto it = std::upper_bound(legs_.begin(), legs_.end(), t, [](double v, const Leg& l) { return v < l.t0; });
  leg = it == legs_.begin() ? &legs_.front() : &*(it - 1);
  const double tau = t - leg->t0;
  const double k = (leg->v1 - leg->v0) / (leg->s1 - leg->s0);
  if (std::abs(k) < 1e-12) {
    speed = leg->v0;
    accel = 0.0;
    return leg->s0 + leg->v0 * tau;
  }
  // dv/ds = k ⇒ v(t) = v0·e^{kτ}, s = s0 + (v0/k)(e^{kτ} − 1), dv/dt = k·v.
  speed = leg->v0 * std::exp(k * tau);
  accel = k * speed;
  return leg->s0 + (speed - leg->v0) / k;
}

/// How long rolling into or out of a turn takes.
constexpr double kRollIn_s = 1.0;

double Trajectory::meanCurvature(double a, double b, double at_s) const {
  const double total = pieces_.back().s0 + pieces_.back().length;
  a = std::max(a, 0.0);
  b = std::min(b, total);
  if (!(b - a > 1e-9)) return at_s;
  // Σ κ_piece · (overlap of the piece with [a, b]) / (b − a): lines have κ = 0.
  double sum = 0.0;
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), a, [](double v, const Piece& pc) { return v < pc.s0; });
  for (auto p = it == pieces_.begin() ? it : it - 1; p != pieces_.end() && p->s0 < b; ++p) {
    if (!p->arc) continue;
    const double overlap = std::min(b, p->s0 + p->length) - std::max(a, p->s0);
    if (overlap > 0.0) sum += (p->turn > 0.0 ? 1.0 : -1.0) / p->radius * overlap;
  }
  return sum / (b - a);
}

TruthState Trajectory::at(double t_s) const {
  TruthState x;
  x.t_s = t_s;
  double v = 0.0, vdot = 0.0;
  const Leg* leg = nullptr;
  const double s = arcLengthAt(t_s, v, vdot, leg);
  Eigen::Vector2d p2, tan2;
  double kappa = 0.0;
  horizontal(s, p2, tan2, kappa);

  // Height: piecewise linear in s with parabolic blends of half-width w around inner stations.
  const std::size_t j = static_cast<std::size_t>(leg - legs_.data());
  const double m = (leg->h1 - leg->h0) / (leg->s1 - leg->s0);
  double h = leg->h0 + m * (s - leg->s0), dh = m, ddh = 0.0;
  auto blend = [&](std::size_t station, double m_in, double m_out, double s_station, double h_station) {
    const double len_in = legs_[station - 1].s1 - legs_[station - 1].s0;
    const double len_out = legs_[station].s1 - legs_[station].s0;
    const double w = std::min({50.0, len_in / 4.0, len_out / 4.0});
    const double d = s - s_station;
    if (std::abs(d) >= w || std::abs(m_out - m_in) < 1e-15) return;
    h = h_station + m_in * d + (m_out - m_in) * (d + w) * (d + w) / (4.0 * w);
    dh = m_in + (m_out - m_in) * (d + w) / (2.0 * w);
    ddh = (m_out - m_in) / (2.0 * w);
  };
  if (j > 0) {
    const Leg& prev = legs_[j - 1];
    blend(j, (prev.h1 - prev.h0) / (prev.s1 - prev.s0), m, leg->s0, leg->h0);
  }
  if (j + 1 < legs_.size()) {
    const Leg& next = legs_[j + 1];
    blend(j + 1, m, (next.h1 - next.h0) / (next.s1 - next.s0), leg->s1, leg->h1);
  }

  const Eigen::Vector2d normal(-tan2.y(), tan2.x());
  x.p_enu_m << p2, h;
  x.v_enu_mps << tan2 * v, dh * v;
  x.a_enu_mps2 << tan2 * vdot + normal * (kappa * v * v), ddh * v * v + dh * vdot;
  x.p_ecef_m = p_origin_ecef_ + R_ecef_enu_ * x.p_enu_m;
  x.v_ecef_mps = R_ecef_enu_ * x.v_enu_mps;
  x.geodetic = maps::ecefToGeodetic(x.p_ecef_m);

  const Eigen::Matrix3d R_enu_ecef_here = maps::rotationEcefToEnu(x.geodetic.lat_rad, x.geodetic.lon_rad);
  const Eigen::Vector3d v_here = R_enu_ecef_here * x.v_ecef_mps;
  x.heading_rad = std::atan2(v_here.x(), v_here.y());
  x.pitch_rad = std::atan2(v_here.z(), v_here.head<2>().norm());
  // Coordinated-turn bank, rolled in and out over kRollIn_s: the curvature averaged over the path
  // flown in ±kRollIn_s/2 (a step in curvature at an arc's ends would otherwise be a step in bank:
  // an angular rate far beyond any airframe's and any gyro's range).
  const double kappa_bank = meanCurvature(s - 0.5 * kRollIn_s * v, s + 0.5 * kRollIn_s * v, kappa);
  x.roll_rad = -std::atan(kappa_bank * v * v / kStandardGravity_mps2);
  x.C_enu_body = bodyToEnu(x.heading_rad, x.pitch_rad, x.roll_rad);
  x.C_ecef_body = R_enu_ecef_here.transpose() * x.C_enu_body;
  return x;
}

std::vector<Waypoint> lawnmower(int lines, double line_length_m, double spacing_m, double height_m, double speed_mps,
                                double heading_rad) {
  if (lines < 1 || !(line_length_m > 0.0) || !(spacing_m > 0.0) || !(speed_mps > 0.0)) {
    throw std::invalid_argument("lawnmower: lines ≥ 1, line length, spacing and speed > 0 are required");
  }
  const Eigen::Vector3d along(std::sin(heading_rad), std::cos(heading_rad), 0.0);
  const Eigen::Vector3d across(std::cos(heading_rad), -std::sin(heading_rad), 0.0);  // to the right
  std::vector<Waypoint> out;
  const Eigen::Vector3d up(0.0, 0.0, height_m);
  for (int i = 0; i < lines; ++i) {
    const Eigen::Vector3d base = up + across * (spacing_m * i);
    const bool forward = i % 2 == 0;
    const Eigen::Vector3d a = forward ? base : base + along * line_length_m;
    const Eigen::Vector3d b = forward ? base + along * line_length_m : base;
    out.push_back({a, speed_mps});
    out.push_back({b, speed_mps});
  }
  return out;
}

}  // namespace skylane::integrity::sim
