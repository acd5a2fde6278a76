#pragma once
/// \file
/// \brief Single-point positioning from RINEX observations and broadcast ephemerides, with RAIM
/// fault detection and exclusion and protection levels at every epoch.
///
/// Pseudorange model (IS-GPS-200N §20.3.3.3.3, Kaplan & Hegarty §7.2):
/// P = ρ + c·(dt_r − dt_s + T_GD·[single frequency]) + I + T + ε, with ρ including the Earth's
/// rotation during the signal flight (Sagnac). Iono-free when two code frequencies exist:
/// P_IF = (f₁²P₁ − f₂²P₂)/(f₁² − f₂²); otherwise the broadcast Klobuchar (GPS) model.

#include "integrity/gnss/rinex_nav.hpp"
#include "integrity/gnss/rinex_obs.hpp"
#include "integrity/pl_summary.hpp"
#include "integrity/raim/raim.hpp"

#include "maps/geodesy.hpp"

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief Which ionosphere treatment SPP uses.
enum class IonoMode {
  kAuto,       ///< iono-free when a second code frequency exists, else Klobuchar
  kIonoFree,   ///< only satellites with two code frequencies
  kKlobuchar,  ///< first frequency only, broadcast model
};

/// \brief Single-point positioning settings.
struct SppConfig {
  double elevation_mask_rad = 15.0 * M_PI / 180.0;
  IonoMode iono = IonoMode::kAuto;
  IntegrityMethod method = IntegrityMethod::kRaim;
  RaimConfig raim;
  AraimConfig araim;  ///< used with IntegrityMethod::kAraim (solution-separation FDE)
  ErrorModel model;
  bool use_galileo = true;
  /// \brief Test hook / what-if: add this bias [m] to a satellite's pseudorange (fault injection).
  std::map<SatId, double> injected_bias_m;
};

/// \brief One epoch's solution.
struct SppEpoch {
  GpsTime t;
  int source_line = 0;
  bool solved = false;
  std::string note;  ///< why not solved / what happened
  Eigen::Vector3d p_ecef = Eigen::Vector3d::Zero();
  maps::Geodetic position;
  double clock_m = 0.0;  ///< receiver clock of the first constellation [m]
  bool iono_free = false;
  std::vector<SatId> used;
  std::vector<SatId> excluded;
  bool fault_detected = false;
  double test_statistic = 0.0;  ///< RAIM: √WSSE; ARAIM: max |Δx|/T over subsets and axes
  double threshold = 0.0;       ///< RAIM: T_d; ARAIM: 1
  PlSummary pl;
};

/// \brief Solves every epoch of `obs` with `nav`. `progress(done, total)` is called now and then.
[[nodiscard]] std::vector<SppEpoch> solveSpp(const ObservationData& obs, const NavigationData& nav,
                                             const SppConfig& cfg,
                                             const std::function<void(std::size_t, std::size_t)>& progress = {});

/// \brief Solves one epoch (exposed for tests and live tracking).
[[nodiscard]] SppEpoch solveSppEpoch(const ObservationEpoch& epoch, const ObservationData& obs,
                                     const NavigationData& nav, const SppConfig& cfg,
                                     const std::optional<Eigen::Vector3d>& initial_ecef);

}  // namespace skylane::integrity
