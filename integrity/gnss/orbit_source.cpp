#include "integrity/gnss/orbit_source.hpp"

#include "maps/parse_error.hpp"

#include <fstream>

#include <algorithm>
#include <cmath>
#include <set>

namespace skylane::integrity {
namespace {

/// Light-time iterations: 3 bring the transmit time to < 1 ns for any GNSS orbit.
constexpr int kLightTimeIterations = 3;

VisibleSatellite lightTimeSolution(const SatId& sat, const Eigen::Vector3d& p_user, const Eigen::Matrix3d& r_enu_ecef, const GpsTime& t,
                        const OrbitSource::StateAt& state_at) {
  double tau = 0.075;  // ≈ 22 000 km / c
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int k = 0; k < kLightTimeIterations; ++k) {
    p = earthRotationCorrection(state_at(t.plus(-tau)).p_ecef, tau);
    tau = (p - p_user).norm() / kSpeedOfLight_mps;
  }
  VisibleSatellite v;
  v.sat = sat;
  v.p_ecef = p;
  v.range_m = (p - p_user).norm();
  v.look = maps::lookAngles(p_user, r_enu_ecef, p);
  return v;
}

}  // namespace

void OrbitSource::addAlmanac(const std::vector<AlmanacRecord>& records, const std::string& file) {
  almanac_.insert(almanac_.end(), records.begin(), records.end());
  files_.push_back(almanacEpochs(file.empty() ? "almanac" : file, records));
}

void OrbitSource::addNavigation(const NavigationData& nav, const std::string& file) {
  nav_.merge(nav);
  files_.push_back(ephemerisEpochs(file.empty() ? "navigation data" : file, nav));
}

void OrbitSource::forEachUsable(const GpsTime& t, const std::function<void(const SatId&, const StateAt&)>& fn,
                                const std::vector<SatId>* only) const {
  const auto wanted = [only](const SatId& sat) { return !only || std::find(only->begin(), only->end(), sat) != only->end(); };
  std::set<SatId> done, nav_sats;
  for (const BroadcastEphemeris& e : nav_.ephemerides) {
    if (wanted(e.sat)) nav_sats.insert(e.sat);
  }
  for (const SatId& sat : nav_sats) {
    const BroadcastEphemeris* eph = selectEphemeris(nav_, sat, t);
    if (!eph) continue;
    done.insert(sat);
    fn(sat, [eph](const GpsTime& tt) { return satelliteState(*eph, tt); });
  }
  for (const AlmanacRecord& a : almanac_) {
    if (a.health != 0 || done.count(a.sat) || !wanted(a.sat)) continue;
    done.insert(a.sat);
    fn(a.sat, [&a](const GpsTime& tt) { return almanacState(a, tt); });
  }
}

std::vector<VisibleSatellite> OrbitSource::visible(const Eigen::Vector3d& p_user, const GpsTime& t,
                                                   double mask_rad) const {
  return located(p_user, t, mask_rad, nullptr);
}

std::vector<VisibleSatellite> OrbitSource::locate(const std::vector<SatId>& sats, const Eigen::Vector3d& p_user,
                                                  const GpsTime& t) const {
  return located(p_user, t, -M_PI / 2.0, &sats);
}

std::vector<VisibleSatellite> OrbitSource::located(const Eigen::Vector3d& p_user, const GpsTime& t, double mask_rad,
                                                   const std::vector<SatId>* only) const {
  std::vector<VisibleSatellite> out;
  const maps::Geodetic user = maps::ecefToGeodetic(p_user);
  const Eigen::Matrix3d r_enu_ecef = maps::rotationEcefToEnu(user.lat_rad, user.lon_rad);  // once, not per satellite
  forEachUsable(t, [&](const SatId& sat, const StateAt& state_at) {
    const VisibleSatellite v = lightTimeSolution(sat, p_user, r_enu_ecef, t, state_at);
    if (v.look.elevation_rad >= mask_rad) out.push_back(v);
  }, only);
  std::sort(out.begin(), out.end(), [](const VisibleSatellite& a, const VisibleSatellite& b) { return a.sat < b.sat; });
  return out;
}

std::vector<std::pair<SatId, Eigen::Vector3d>> OrbitSource::positionsForAllUsers(const GpsTime& t) const {
  constexpr double kNominalFlight_s = 0.075;
  std::vector<std::pair<SatId, Eigen::Vector3d>> out;
  const GpsTime t_tx = t.plus(-kNominalFlight_s);
  forEachUsable(t, [&](const SatId& sat, const StateAt& state_at) {
    out.emplace_back(sat, earthRotationCorrection(state_at(t_tx).p_ecef, kNominalFlight_s));
  });
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  return out;
}

std::vector<OrbitFileAge> OrbitSource::fileAges(const GpsTime& t) const {
  std::vector<OrbitFileAge> out;
  for (const OrbitFileEpochs& f : files_) out.push_back(orbitFileAge(f, t));
  return out;
}

OrbitSource loadOrbitFiles(const std::vector<std::string>& files, const std::string& source, const std::string& field) {
  OrbitSource orbits;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string& f = files[i];
    std::ifstream in(f);
    if (!in) {
      throw maps::ParseError(source, 0, field + "[" + std::to_string(i) + "]", f,
                             "a readable YUMA/SEM almanac or RINEX navigation file");
    }
    std::string first;
    std::getline(in, first);
    if (first.find("RINEX VERSION") != std::string::npos) {
      orbits.addNavigation(loadRinexNav(f), f);
    } else {
      orbits.addAlmanac(loadAlmanac(f), f);
    }
  }
  if (orbits.empty()) throw maps::ParseError(source, 0, field, "", "files that hold at least one satellite");
  return orbits;
}

}  // namespace skylane::integrity
