#pragma once
/// \file
/// \brief Where satellite positions come from for prediction: almanacs or broadcast ephemerides.

#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/orbit_age.hpp"
#include "integrity/gnss/rinex_nav.hpp"

#include "maps/geodesy.hpp"

#include <functional>
#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief A satellite seen from a place at an instant.
struct VisibleSatellite {
  SatId sat;
  Eigen::Vector3d p_ecef = Eigen::Vector3d::Zero();  ///< at transmit time, in the reception ECEF frame
  maps::LookAngles look;
  double range_m = 0.0;
};

/// \brief A set of orbits: almanac records and/or broadcast ephemerides.
class OrbitSource {
 public:
  /// \brief A satellite's state as a function of GPS time.
  using StateAt = std::function<SatelliteState(const GpsTime&)>;

  /// \brief Adds almanac records (unhealthy ones are kept and skipped at use); `file` names
  /// them in fileAges() ("almanac" when empty).
  void addAlmanac(const std::vector<AlmanacRecord>& records, const std::string& file = {});
  /// \brief Adds a navigation file's ephemerides; `file` names them in fileAges()
  /// ("navigation data" when empty).
  void addNavigation(const NavigationData& nav, const std::string& file = {});

  /// \brief All satellites above `mask_rad` seen from `p_user_ecef` at reception time t, with the
  /// light-time iteration and Earth-rotation correction applied. Ephemerides win over almanac
  /// entries for the same satellite when one is valid at t.
  [[nodiscard]] std::vector<VisibleSatellite> visible(const Eigen::Vector3d& p_user_ecef, const GpsTime& t,
                                                      double mask_rad) const;
  /// \brief The satellites of `sats` that have a usable orbit at t, seen from `p_user_ecef`
  /// whatever their elevation: visible()'s light-time solution for these satellites only (a
  /// receiver's ranges name the few it tracks; the rest of the constellation is not computed).
  [[nodiscard]] std::vector<VisibleSatellite> locate(const std::vector<SatId>& sats, const Eigen::Vector3d& p_user_ecef,
                                                     const GpsTime& t) const;
  /// \brief Every healthy satellite's ECEF position for a user anywhere on Earth at time t:
  /// evaluated 75 ms (a typical flight time) before t and turned by the Earth's rotation over
  /// those 75 ms. Against the per-user light-time solution of visible() the direction differs by
  /// < 2e-5 rad (≈ 1 mdeg of elevation) — for worldwide availability maps.
  [[nodiscard]] std::vector<std::pair<SatId, Eigen::Vector3d>> positionsForAllUsers(const GpsTime& t) const;
  /// \brief Each added file's age at the mission's time t (orbit_age.hpp), in the order added.
  [[nodiscard]] std::vector<OrbitFileAge> fileAges(const GpsTime& t) const;
  [[nodiscard]] bool empty() const { return almanac_.empty() && nav_.ephemerides.empty(); }
  [[nodiscard]] std::size_t size() const { return almanac_.size() + nav_.ephemerides.size(); }

 private:
  /// Calls fn for every satellite usable at t (of `only`, when given): a valid broadcast
  /// ephemeris wins over the almanac.
  void forEachUsable(const GpsTime& t, const std::function<void(const SatId&, const StateAt&)>& fn,
                     const std::vector<SatId>* only = nullptr) const;
  /// The located satellites above mask_rad (of `only`, when given), sorted by satellite.
  [[nodiscard]] std::vector<VisibleSatellite> located(const Eigen::Vector3d& p_user_ecef, const GpsTime& t, double mask_rad,
                                                      const std::vector<SatId>* only) const;

  std::vector<AlmanacRecord> almanac_;
  NavigationData nav_;
  std::vector<OrbitFileEpochs> files_;
};

/// \brief Loads almanacs (YUMA/SEM) and RINEX navigation files, told apart by the RINEX header
/// line. `source` and `field` name where the list came from (e.g. a mission file and "$.orbits")
/// in errors.
/// \throws maps::ParseError naming source, field[i] and the file when it cannot be read, or the
/// file's own parse error; and when the files hold no satellite at all.
[[nodiscard]] OrbitSource loadOrbitFiles(const std::vector<std::string>& files, const std::string& source,
                                         const std::string& field);

}  // namespace skylane::integrity
