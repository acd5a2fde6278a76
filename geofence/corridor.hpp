#pragma once
/// \file
/// \brief The two box levels (docs/method.md §6; US 10,466,362 claims 8 and 9):
/// alert limits from the vehicle's size, first-level corridor and second-level airspace boxes
/// along a path, and whether a protection volume lies inside them, with margins.
///
/// Frame: the **mission map frame** — x east and y north in metres in the azimuthal
/// equidistant plane at the mission origin (maps::PlaneFrame), z the WGS-84 ellipsoidal
/// height [m]. The protection volume is a vertical cylinder (radius HPL, half-height VPL), so
/// the vertical axis is the local vertical, as the protection levels are.

#include <Eigen/Core>

#include <array>
#include <utility>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace skylane::geofence {

/// \brief A dimension of the vehicle.
enum class Dimension { kLateral, kLongitudinal, kHeight };

/// \brief The vehicle's size [m]: span, length and height.
struct Vehicle {
  double lateral_m = 0.0;
  double longitudinal_m = 0.0;
  double height_m = 0.0;
};

/// \brief Which dimension each alert limit scales. The patent's mapping (US 10,466,362) is the default: the
/// horizontal limit from the lateral size, the vertical one from the longitudinal size.
struct AlertMapping {
  Dimension horizontal = Dimension::kLateral;
  Dimension vertical = Dimension::kLongitudinal;
};

/// \brief The box-level factors: k₁ ∈ [1.1, 1.3] (corridor), k₂ ∈ [100, 1000] (airspace).
struct BoxLevels {
  double k1 = 1.2;
  double k2 = 300.0;
  AlertMapping mapping;
  bool override_ranges = false;  ///< accept k outside its range, with a warning
};

/// \brief Horizontal and vertical alert limits (half-width and half-height of a box) [m].
struct AlertLimits {
  double hal_m = 0.0;
  double val_m = 0.0;
};

/// \brief Both levels' limits and the warnings an override produced.
struct LevelLimits {
  AlertLimits level1;
  AlertLimits level2;
  std::vector<std::string> warnings;
};

/// \brief HAL_n = k_n · (mapped horizontal size), VAL_n = k_n · (mapped vertical size).
/// \throws std::invalid_argument for a non-positive or non-finite mapped size, or for a k
/// outside its range without override_ranges (the message names k, its value and the range).
[[nodiscard]] LevelLimits alertLimits(const Vehicle& vehicle, const BoxLevels& levels);

/// \brief A protection volume: vertical cylinder of radius HPL and half-height VPL round the
/// estimated position (map frame).
struct ProtectionVolume {
  Eigen::Vector3d p_map = Eigen::Vector3d::Zero();
  double hpl_m = 0.0;
  double vpl_m = 0.0;
};

/// \brief Checks a volume at a public entry point.
/// \throws std::invalid_argument for a non-finite position or a negative/non-finite PL.
void requireValid(const ProtectionVolume& volume);

/// \brief Three-valued verdict: indeterminate when the deciding margin is within the
/// tolerance of zero (touching counts as neither inside nor outside).
enum class Verdict { kInside, kOutside, kIndeterminate };

/// \brief "inside", "outside", "indeterminate".
[[nodiscard]] const char* verdictName(Verdict v);

/// \brief The result of a containment check.
struct Containment {
  Verdict verdict = Verdict::kOutside;
  /// The segment whose piece holds the volume (or the nearest, when outside).
  std::size_t segment = 0;
  bool across_joint = false;  ///< held by the union of neighbouring pieces, by no single one
  /// How much HPL (resp. VPL) could still grow and the volume stay inside; negative: by how
  /// much it sticks out. For one piece both are exact: the horizontal one HAL − d − HPL (d the
  /// centre's distance to the segment), the vertical one over the whole disk, the centre line's
  /// height taken at each point's nearest point of the segment — so the climb counts only over
  /// the part of the disk that projects inside the segment, and over the end caps (the
  /// half-disks beyond a waypoint) the height is the waypoint's (docs/method.md §6, end caps).
  /// (On a sloping segment a larger HPL also moves the vertical band: margin_h is the horizontal
  /// room alone.) Hence a volume that reaches one piece only — a path's ends among them — is
  /// decided exactly, up to the tolerance. Across a joint (the volume reaches several pieces and
  /// their union holds it better than any one piece, by more than the tolerance) margin_v holds
  /// the one combined margin L, and margin_h max(L, the best piece's horizontal margin) (the
  /// union's horizontal room is at least that piece's; so margin_h does not jump where the union
  /// stops helping and the vertical margin decides). L is min over the volume's columns
  /// (the vertical segments through its disk) of how far the column lies inside the union of
  /// the pieces — the largest δ such that the column grown by δ up and down lies in the height
  /// bands of pieces whose horizontal margin there is ≥ δ (two pieces' bands may cover a column
  /// together) — certified from below to within max(tolerance, HAL/1000) by branch and bound.
  /// It is a lower bound on how much VPL could grow, and indicates HPL's room. A larger PL
  /// never turns a verdict into "inside" except, across a joint, within that accuracy.
  double margin_h_m = 0.0;
  double margin_v_m = 0.0;
};

/// \brief Operating limits of the mission that clip the boxes vertically [m, ellipsoidal].
struct OperatingLimits {
  double floor_h_ell_m = -std::numeric_limits<double>::infinity();
  double ceiling_h_ell_m = std::numeric_limits<double>::infinity();
};

namespace detail {
struct LegBounds;  ///< corridor.cpp: bounds on a point's distance to each leg
/// \brief A segment as the margins read it, computed once: its ends, horizontal direction
/// b − a and length, its horizontal bounding box, and the unit normal n of its line with
/// n·a (zero for a vertical segment), so that |n·x − n·a| is x's distance to the line.
struct CorridorLeg {
  Eigen::Vector3d a, b;
  Eigen::Vector2d d;
  double length_m;
  Eigen::Vector2d box_lo, box_hi;
  Eigen::Vector2d normal;
  double normal_offset_m;
};
}  // namespace detail

/// \brief Boxes along a path: one per segment, half-width HAL and half-height VAL round the
/// centre line, and a vertical cylinder of radius HAL at each waypoint covering the joint (and
/// the path's ends). A segment's **piece** is the set of points whose horizontal distance to
/// the segment is ≤ HAL and whose height is within VAL of the centre line at the nearest
/// point of the segment (the box plus the halves of the two end cylinders).
class Corridor {
 public:
  /// \brief The path (map frame, ≥ 2 waypoints, finite), the limits and the operating limits.
  /// \throws std::invalid_argument for fewer than 2 waypoints, a non-finite coordinate or
  /// non-positive limits.
  Corridor(std::vector<Eigen::Vector3d> path_map, AlertLimits limits, OperatingLimits operating = {});

  /// \brief The waypoints.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& path() const { return path_; }
  /// \brief HAL and VAL.
  [[nodiscard]] const AlertLimits& limits() const { return limits_; }
  /// \brief Number of segments.
  [[nodiscard]] std::size_t segmentCount() const { return path_.size() - 1; }

  /// \brief The segment's box as 8 corners (bottom four, then top four, counter-clockwise seen
  /// from above): a box along the horizontal direction of the segment, sheared to follow its
  /// climb; a convex hexahedron for the collision library.
  [[nodiscard]] std::array<Eigen::Vector3d, 8> segmentBoxCorners(std::size_t segment) const;

  /// \brief Whether the protection volume lies inside one piece or inside the union of the
  /// pieces it touches (across a joint), and within the operating limits. `tolerance_m`: a
  /// deciding margin with |margin| ≤ tolerance is indeterminate.
  /// \throws std::invalid_argument for a non-finite position, a negative/non-finite PL or a
  /// negative/non-finite tolerance.
  [[nodiscard]] Containment contains(const ProtectionVolume& volume, double tolerance_m = 1e-6) const;
  /// \brief {contains(volume, tolerance_m), other.contains(volume, tolerance_m)}, the same
  /// answers; when both corridors lie on the same path (the same waypoints, bit for bit: a fence's
  /// two levels) the bounds on the centre's distance to each leg are computed once for both.
  [[nodiscard]] std::pair<Containment, Containment> containsWith(const Corridor& other, const ProtectionVolume& volume,
                                                                 double tolerance_m = 1e-6) const;

 private:
  /// contains(), with the legs' distance bounds for the volume's centre in `bounds`: computed
  /// there unless `bounds_known` (another corridor on the same path computed them for it).
  [[nodiscard]] Containment containsWithBounds(const ProtectionVolume& volume, double tolerance_m, detail::LegBounds& bounds,
                                               bool bounds_known) const;

  std::vector<Eigen::Vector3d> path_;
  std::vector<detail::CorridorLeg> legs_;  ///< one per segment
  AlertLimits limits_;
  OperatingLimits operating_;
};

}  // namespace skylane::geofence
