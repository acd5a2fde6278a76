#pragma once
/// \file
/// \brief The one integrity call for an epoch of pseudoranges: the position, the protection levels
/// with the chosen method, and fault detection and exclusion on demand. Live corridor tracking
/// calls it with a fix's raw ranges (solveLiveFix); single-point positioning from RINEX
/// (spp.hpp) calls it with ranges corrected from the broadcast ephemerides (solveEpoch).
///
/// Measurement model: P_i = |r_s,i − r| + c·δt_r,c(i) + ε_i, with r_s,i the satellite's position
/// at transmit time in the reception ECEF frame (light time and Sagnac applied, as
/// OrbitSource::visible gives it), c(i) the satellite's constellation (one receiver clock each)
/// and P_i already corrected for the satellite clock (and, dual frequency, iono-free): what a
/// receiver's raw output or the simulator gives. Linearised WLS from the reported position
/// (Kaplan & Hegarty, 3rd ed., §7.3), the troposphere/ionosphere in the σ's of the error model.
///
/// Two passes, as live tracking uses them:
/// - **first pass** (`exclude = false`): all satellites in view, detection only. When the
///   detection test fires (RAIM χ² on the LSR, or any ARAIM solution-separation test), the
///   fault-free protection level no longer bounds the error: the fix's PL becomes
///   PL_det = PL + max_i |Δx_i| (horizontal: the horizontal norm, vertical: |Δx_U|), Δx_i the
///   shift of the solution when satellite i (ARAIM: each monitored subset) is left out — the
///   displacement the data themselves show a fault could have caused. (skylane's reading: the
///   source documents give no PL for a detected, not yet excluded fault (docs/method.md §3.4); this one grows with the fault and
///   falls back to the fault-free PL once the fault is excluded.)
/// - **monitoring rerun** (`exclude = true`): the method's FDE (RAIM w-test, ARAIM
///   solution-separation exclusion), the position and PLs of the remaining geometry.

#include "integrity/gnss/orbit_source.hpp"
#include "integrity/gnss/satellite_id.hpp"
#include "integrity/pl_summary.hpp"
#include "maps/geodesy.hpp"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief One pseudorange of a live epoch.
struct RawRange {
  SatId sat;
  double pr_m = 0.0;  ///< corrected pseudorange [m] (see the file comment)
  /// \brief The satellite at transmit time (reception ECEF frame); computed from the orbits when
  /// absent.
  std::optional<Eigen::Vector3d> sat_ecef_m;
};

/// \brief A pseudorange with its satellite's position.
struct LocatedRange {
  SatId sat;
  double pr_m = 0.0;
  Eigen::Vector3d sat_ecef_m = Eigen::Vector3d::Zero();
};

/// \brief The ranges with their satellites' positions: as given, else from `orbits` (transmit time,
/// Sagnac: OrbitSource::visible seen from `x0_ecef` at `t`); a range with neither goes to `missing`.
/// \throws std::invalid_argument for a non-finite pseudorange or satellite position.
[[nodiscard]] std::vector<LocatedRange> locateRanges(const std::vector<RawRange>& ranges, const Eigen::Vector3d& x0_ecef,
                                                     const GpsTime& t, const OrbitSource* orbits, std::vector<SatId>& missing);

/// \brief locateRanges() seen from `r_ecef` at `t`, keeping the satellites at or above
/// `elevation_mask_rad` (those without a position or orbit are left out).
[[nodiscard]] std::vector<LocatedRange> rangesAboveMask(const std::vector<RawRange>& ranges, const Eigen::Vector3d& r_ecef,
                                                        const GpsTime& t, const OrbitSource* orbits, double elevation_mask_rad);

/// \brief The receiver clock bias [m] at `r_ecef`: the mean residual ρ − |r_s − r| of the
/// satellites in `used`; std::nullopt when none of them has a range.
[[nodiscard]] std::optional<double> meanClockResidual_m(const std::vector<RawRange>& ranges, const Eigen::Vector3d& r_ecef,
                                                        const GpsTime& t, const OrbitSource* orbits,
                                                        const std::vector<SatId>& used);

/// \brief What a live epoch is solved with.
struct LiveFixConfig {
  IntegrityMethod method = IntegrityMethod::kRaim;
  ErrorModel model;
  RaimConfig raim;
  AraimConfig araim;
  double elevation_mask_rad = 5.0 * M_PI / 180.0;
};

struct LiveEpoch;

/// \brief The outcome of one live epoch.
struct LiveFix {
  bool solved = false;
  std::string note;  ///< why not solved, or what happened
  Eigen::Vector3d p_ecef = Eigen::Vector3d::Zero();
  maps::Geodetic position;
  std::vector<SatId> used;
  std::vector<SatId> excluded;
  std::vector<SatId> missing_orbit;  ///< satellites with neither a position nor an orbit
  bool fault_detected = false;       ///< the detection test of the all-in-view solution fired
  bool fault_excluded = false;
  PlSummary pl;                      ///< of the final geometry (first pass: PL_det when detected)
  double clock_m = 0.0;              ///< receiver clock of the first constellation in the geometry [m]
  double test_statistic = 0.0;       ///< of the final geometry: RAIM √WSSE (normalised), ARAIM max |Δx|/T
  double threshold = 0.0;            ///< RAIM T_d (0 without redundancy), ARAIM 1
  double fault_free_hpl_m = 0.0, fault_free_vpl_m = 0.0;  ///< the PL before the detection term
  /// solveLiveFix without `exclude`: its ranges and all-in-view solution, for excludeFaults().
  std::shared_ptr<const LiveEpoch> epoch;
};

/// \brief The epoch's ranges seen from a linearisation point (ECEF [m]): the satellites in the
/// reception frame and the pseudoranges with every correction that depends on the point applied
/// (atmosphere, Earth rotation). Returns the same satellites in the same order at every point.
using RangesSeenFrom = std::function<const std::vector<LocatedRange>&(const Eigen::Vector3d& x_ecef)>;

/// \brief Solves one epoch from `x0_ecef`: iterated WLS over every range above the mask, the
/// method's detection test at the converged point and, with `exclude`, its exclusion and the
/// solution of the remaining geometry (see the file comment for the two passes).
[[nodiscard]] LiveFix solveEpoch(const RangesSeenFrom& ranges_from, const Eigen::Vector3d& x0_ecef,
                                 const LiveFixConfig& cfg, bool exclude);

/// \brief solveLiveFix's exclusion pass on a first pass made without it: the method's FDE on
/// the first pass's all-in-view solution, the kept ranges solved and checked (solveEpoch's
/// second step), without solving the all-in-view geometry again. Without a detection it is the
/// first pass. `cfg` is the first pass's. The tracker's monitoring rerun: the FDE on the very
/// solution whose test fired (before, it solved the epoch again from that solution's position).
/// \throws std::invalid_argument when `first` has no epoch (it did not solve, or it was made
/// with `exclude`).
[[nodiscard]] LiveFix excludeFaults(const LiveFix& first, const LiveFixConfig& cfg);

/// \brief Solves one live epoch with solveEpoch(). `initial` is the reported position (the linearisation point);
/// `orbits` gives satellite positions a range does not carry (nullptr: every range must).
/// \throws std::invalid_argument for a non-finite pseudorange or position.
[[nodiscard]] LiveFix solveLiveFix(const std::vector<RawRange>& ranges, const maps::Geodetic& initial, const GpsTime& t,
                                   const LiveFixConfig& cfg, bool exclude, const OrbitSource* orbits);

}  // namespace skylane::integrity
