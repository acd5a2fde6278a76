#include "integrity/predict.hpp"

#include "tests/test_util.hpp"

namespace skylane::integrity {
namespace {

/// The DO-229 MOPS almanac (24 GPS satellites).
OrbitSource mopsOrbits() {
  OrbitSource orbits;
  orbits.addAlmanac(loadAlmanac(test::dataPath("gnss/almmops.txt")));
  return orbits;
}

TEST(Predict, MopsConstellationGivesRaimEverywhereOverADayInJapan) {
  const OrbitSource orbits = mopsOrbits();
  PredictRequest req;
  req.place = {maps::deg2rad(35.0), maps::deg2rad(139.0), 0.0};
  req.start = *parseRfc3339("2020-01-01T00:00:00Z");
  req.duration_s = 86400;
  req.step_s = 900;
  const auto s = predictIntegrity(orbits, req, IntegrityMethod::kRaim);
  ASSERT_EQ(s.size(), 97u);
  for (const auto& p : s) {
    // The 24-satellite DO-229 constellation shows 6 … 12 satellites above 5° at mid latitudes.
    EXPECT_GE(p.sats.size(), 6u);
    EXPECT_LE(p.sats.size(), 12u);
    EXPECT_TRUE(p.pl.pl_computed) << formatRfc3339(p.t) << ": " << p.pl.reason;
    EXPECT_GT(p.dops.hdop, 0.5);
    EXPECT_LT(p.dops.hdop, 10);
  }
}

TEST(Predict, EphemerisAndAlmanacAgreeOnWhatIsVisible) {
  // The 2005 broadcast ephemerides against the real almanac? None for 2005 is shipped, so
  // check self-consistency instead: satellites from the navigation file match SPP's sky.
  OrbitSource orbits;
  orbits.addNavigation(loadRinexNav(test::dataPath("gnss/30400920.05n")));
  const Eigen::Vector3d site(-3978242.4348, 3382841.1715, 3649902.7667);
  const auto vis = orbits.visible(site, GpsTime{1316, 518400.0}, maps::deg2rad(0));
  std::vector<std::string> ids;
  for (const auto& v : vis) ids.push_back(v.sat.str());
  // The observation file's first epoch tracks G03 G07 G08 G11 G19 G20 G24 G27 G28.
  for (const char* id : {"G03", "G07", "G08", "G11", "G19", "G20", "G24", "G27", "G28"}) {
    EXPECT_NE(std::find(ids.begin(), ids.end(), id), ids.end()) << id;
  }
  for (const auto& v : vis) EXPECT_NEAR(v.range_m, (v.p_ecef - site).norm(), 1e-6);
}

TEST(Predict, DopsOfASymmetricSky) {
  // Four satellites 90° apart at 0° elevation plus zenith: HDOP = VDOP·… closed form check.
  std::vector<SatLook> s;
  for (int i = 0; i < 4; ++i) s.push_back({{Constellation::kGps, i + 1}, {i * M_PI / 2, 0.0}});
  s.push_back({{Constellation::kGps, 5}, {0.0, M_PI / 2}});
  const Dops d = computeDops(buildGeometry(s, ErrorModel{}, 9.0));
  // GᵀG = diag(2, 2, 1, 5) with coupling −1 between up and clock: P_EE = P_NN = 1/2.
  EXPECT_NEAR(d.hdop, 1.0, 1e-12);
  EXPECT_NEAR(d.vdop, std::sqrt(5.0 / 4.0), 1e-12);
}

TEST(Predict, ASatelliteBehindABuildingIsDropped) {
  // GIVEN the MOPS constellation over Zürich at one epoch, and the lowest satellite above 15°
  const OrbitSource orbits = mopsOrbits();
  PredictRequest req;
  req.place = {maps::deg2rad(47.3769), maps::deg2rad(8.5417), 450.0};
  req.start = *parseRfc3339("2020-01-01T00:00:00Z");
  req.duration_s = 0;
  const PredictSample open_sky = predictIntegrity(orbits, req, IntegrityMethod::kRaim).front();
  const SatLook* target = nullptr;
  for (const SatLook& s : open_sky.sats) {
    if (s.look.elevation_rad > maps::deg2rad(15) && (!target || s.look.elevation_rad < target->look.elevation_rad)) target = &s;
  }
  ASSERT_NE(target, nullptr);
  // WHEN a building 20 m away in its direction, 10 m wide, rises 5° above it
  const double az = target->look.azimuth_rad, d = 20.0;
  const double height = 1.5 + d * std::tan(target->look.elevation_rad + maps::deg2rad(5));
  const maps::LocalFrame frame({req.place.lat_rad, req.place.lon_rad, 448.5});
  const Eigen::Vector2d u(std::sin(az), std::cos(az)), v(std::cos(az), -std::sin(az));
  maps::Building b;
  for (const auto& [across, along] : {std::pair{-5.0, d}, {5.0, d}, {5.0, d + 8}, {-5.0, d + 8}}) {
    const Eigen::Vector2d p = across * v + along * u;
    const maps::Geodetic g = frame.fromEnu({p.x(), p.y(), 0});
    b.ring_lat_lon_rad.emplace_back(g.lat_rad, g.lon_rad);
  }
  b.base_h_ell_m = 448.5;
  b.top_h_ell_m = 448.5 + height;
  const maps::BuildingIndex index({b});
  req.sky_mask = maps::computeSkyMask(req.place, &index, nullptr);
  const PredictSample masked = predictIntegrity(orbits, req, IntegrityMethod::kRaim).front();
  // THEN that satellite is gone, counted as blocked, and every satellite left was in the open sky
  EXPECT_GE(masked.blocked, 1u);
  EXPECT_EQ(masked.sats.size() + masked.blocked, open_sky.sats.size());
  for (const SatLook& s : masked.sats) {
    EXPECT_NE(s.sat.str(), target->sat.str());
    EXPECT_TRUE(req.sky_mask->isVisible(s.look)) << s.sat.str();
  }
}

}  // namespace
}  // namespace skylane::integrity
