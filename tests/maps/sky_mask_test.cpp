// Sky mask: blocked elevation per azimuth bin from buildings and terrain (maps/sky_mask.hpp).
#include "maps/sky_mask.hpp"

#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "tests/maps/raster_fixture.hpp"
#include "tests/test_util.hpp"

#include <random>

namespace skylane::maps {
namespace {

/// Angles computed two ways from the same geometry agree to rounding of atan2 and the frame
/// conversions (nanometres at hundreds of metres).
constexpr double kAngleTol_rad = 1e-7;
/// The prime-vertical radius, written out here independently of the code under test.
double primeVertical_m(double lat_rad) {
  const double a = 6378137.0, f = 1.0 / 298.257223563, e2 = f * (2 - f);
  return a / std::sqrt(1 - e2 * std::sin(lat_rad) * std::sin(lat_rad));
}

const Geodetic kGround{deg2rad(47.3769), deg2rad(8.5417), 450.0};  // a street in Zürich, h_ell
constexpr double kEye_m = 1.5;

/// A building whose footprint is given in metres in the ENU frame of kGround, standing on
/// kGround's height, `height_m` tall.
Building building(const std::vector<Eigen::Vector2d>& footprint_en, double height_m, const Geodetic& ground = kGround) {
  const LocalFrame frame(ground);
  Building b;
  b.source = "test";
  b.feature = "test building";
  for (const Eigen::Vector2d& p : footprint_en) {
    const Geodetic g = frame.fromEnu({p.x(), p.y(), 0.0});
    b.ring_lat_lon_rad.emplace_back(g.lat_rad, g.lon_rad);
  }
  b.base_h_ell_m = ground.h_ell_m;
  b.top_h_ell_m = ground.h_ell_m + height_m;
  return b;
}

std::vector<Eigen::Vector2d> box(double e0, double n0, double e1, double n1) { return {{e0, n0}, {e1, n0}, {e1, n1}, {e0, n1}}; }

Geodetic eye(const Geodetic& g = kGround, double above_m = kEye_m) { return {g.lat_rad, g.lon_rad, g.h_ell_m + above_m}; }

// --- the SkyMask container -----------------------------------------------------------------

TEST(SkyMask, BinsAreHalfOpenClockwiseFromNorthAndWrap) {
  SkyMask m;  // 1°
  EXPECT_EQ(m.bins(), 360);
  EXPECT_EQ(m.binOf(0.0), 0);
  EXPECT_EQ(m.binOf(deg2rad(0.999)), 0);
  EXPECT_EQ(m.binOf(deg2rad(1.0) + 1e-12), 1);
  EXPECT_EQ(m.binOf(deg2rad(359.5)), 359);
  EXPECT_EQ(m.binOf(deg2rad(-0.5)), 359);
  EXPECT_EQ(m.binOf(deg2rad(360.0)), 0);
  EXPECT_EQ(m.binOf(deg2rad(725.5)), 5);
  EXPECT_EQ(SkyMask(deg2rad(0.1)).bins(), 3600);
  EXPECT_EQ(SkyMask(deg2rad(5)).bins(), 72);
  EXPECT_THROW(SkyMask(deg2rad(7)), std::invalid_argument);
  EXPECT_THROW(SkyMask(0.0), std::invalid_argument);
  EXPECT_THROW(SkyMask(NAN), std::invalid_argument);
  EXPECT_THROW((void)m.binOf(NAN), std::invalid_argument);
}

TEST(SkyMask, ARayGrazingTheBlockedElevationIsBlocked) {
  SkyMask m(deg2rad(10));
  m.raise(3, deg2rad(20));
  EXPECT_FALSE(m.isVisible({deg2rad(35), deg2rad(20)}));
  EXPECT_TRUE(m.isVisible({deg2rad(35), deg2rad(20.001)}));
  EXPECT_TRUE(m.isVisible({deg2rad(45), deg2rad(0.5)}));
  EXPECT_FALSE(m.isVisible({deg2rad(45), kOpenSky_rad}));
}

// --- buildings, against numbers worked out by hand ------------------------------------------

TEST(SkyMaskBuildings, ABoxToTheNorthBlocksAtanOfItsHeightOverItsDistance) {
  // GIVEN a 20 m wide, 20 m tall building whose near face is 50 m north of the observer
  const double d = 50.0, H = 20.0, half_w = 10.0;
  const BuildingIndex index({building(box(-half_w, d, half_w, d + 10), H)});
  const SkyMask m = computeSkyMask(eye(), &index, nullptr);
  const double R = primeVertical_m(kGround.lat_rad);
  const auto e = [&](double dist) { return std::atan2(H - kEye_m - dist * dist / (2 * R), dist); };
  // THEN the bins that face it carry atan((H − h)/d) (with the 0.2 mm drop at 50 m)
  EXPECT_NEAR(m.binBlocked_rad(0), e(d), kAngleTol_rad);
  EXPECT_NEAR(m.binBlocked_rad(359), e(d), kAngleTol_rad);
  // a bin off the axis sees the face first at its edge nearer north: d / cos(az)
  EXPECT_NEAR(m.binBlocked_rad(5), e(d / std::cos(deg2rad(5))), kAngleTol_rad);
  EXPECT_NEAR(m.binBlocked_rad(354), e(d / std::cos(deg2rad(5))), kAngleTol_rad);
  EXPECT_NEAR(m.binBlocked_rad(11), e(d / std::cos(deg2rad(11))), kAngleTol_rad);
  // AND it covers 2·atan(w/2 / d) = 22.62°: bins 348 … 359 and 0 … 11, no others
  const double half_deg = rad2deg(std::atan(half_w / d));
  ASSERT_NEAR(half_deg, 11.31, 0.01);
  int covered = 0;
  for (int k = 0; k < 360; ++k) {
    const bool blocked = m.binBlocked_rad(k) > kOpenSky_rad;
    covered += blocked ? 1 : 0;
    const bool expected = k < std::ceil(half_deg) || k >= 360 - std::ceil(half_deg);
    EXPECT_EQ(blocked, expected) << "bin " << k;
  }
  EXPECT_EQ(covered, 24);
  EXPECT_TRUE(m.isVisible({deg2rad(12.5), deg2rad(1)}));
  EXPECT_FALSE(m.isVisible({deg2rad(0.5), deg2rad(15)}));
}

TEST(SkyMaskBuildings, FrameInvarianceTheSameBuildingInEveryDirection) {
  // The 50 m building above, turned to 8 azimuths: the facing bin always holds the same value.
  const double d = 50.0, H = 20.0;
  const double R = primeVertical_m(kGround.lat_rad);
  for (int k = 0; k < 8; ++k) {
    const double az = deg2rad(45.0 * k + 0.5);  // the middle of bin 45k
    const Eigen::Vector2d u(std::sin(az), std::cos(az)), v(std::cos(az), -std::sin(az));
    std::vector<Eigen::Vector2d> fp;
    for (const Eigen::Vector2d& c : box(-10, d, 10, d + 10)) fp.push_back(c.x() * v + c.y() * u);
    const BuildingIndex index({building(fp, H)});
    const SkyMask m = computeSkyMask(eye(), &index, nullptr);
    // The bin [45k, 45k+1) spans ±0.5° about the face's normal: the foot of the normal is in it.
    EXPECT_NEAR(m.binBlocked_rad(45 * k), std::atan2(H - kEye_m - 0, d), 1e-5) << "azimuth " << 45 * k;
    EXPECT_NEAR(m.binBlocked_rad(45 * k), std::atan2(H - kEye_m - d * d / (2 * R), d), kAngleTol_rad) << "azimuth " << 45 * k;
  }
}

TEST(SkyMaskBuildings, EarthCurvatureLowersABuildingThreeKilometresAway) {
  // GIVEN a 100 m tower block 3 km east (its near face 200 m wide)
  const double d = 3000.0, H = 100.0;
  const BuildingIndex index({building(box(d, -100, d + 30, 100), H)});
  const SkyMask m = computeSkyMask(eye(), &index, nullptr);
  const double R = primeVertical_m(kGround.lat_rad);
  const double drop = d * d / (2 * R);
  ASSERT_NEAR(drop, 0.704, 0.001);
  // THEN bin 90 shows atan2(H − h − d²/2R, d), 0.013° below the flat-Earth angle
  EXPECT_NEAR(m.binBlocked_rad(89), std::atan2(H - kEye_m - drop, d), 1e-6);
  EXPECT_NEAR(m.binBlocked_rad(90), std::atan2(H - kEye_m - drop, d), 1e-6);
  EXPECT_GT(std::atan2(H - kEye_m, d) - m.binBlocked_rad(90), 2e-4);
  // AND with standard radio refraction (k = 4/3) the drop is 3/4 of that
  SkyMaskOptions refr;
  refr.refraction_k = 4.0 / 3.0;
  EXPECT_NEAR(computeSkyMask(eye(), &index, nullptr, refr).binBlocked_rad(90), std::atan2(H - kEye_m - 0.75 * drop, d), 1e-6);
}

TEST(SkyMaskBuildings, InsideAFootprintBelowItsTopEverythingIsBlocked) {
  const BuildingIndex index({building(box(-20, -20, 30, 15), 12.0), building(box(100, 100, 120, 120), 50.0)});
  const SkyMask m = computeSkyMask(eye(kGround, 3.0), &index, nullptr);
  for (int k = 0; k < m.bins(); ++k) EXPECT_EQ(m.binBlocked_rad(k), M_PI / 2) << k;
  // On its wall (the boundary counts as inside)
  const Geodetic on_wall = LocalFrame(kGround).fromEnu({-20, 0, 3.0});
  EXPECT_EQ(computeSkyMask(on_wall, &index, nullptr).binBlocked_rad(123), M_PI / 2);
  // On its roof: the roof is below, the other building still shows
  const SkyMask roof = computeSkyMask(eye(kGround, 12.5), &index, nullptr);
  EXPECT_LT(roof.binBlocked_rad(180), 0.0);
  EXPECT_GT(roof.binBlocked_rad(45), deg2rad(10));
}

TEST(SkyMaskBuildings, ADroneAboveTheRoofsSeesThemBelowTheHorizon) {
  // 100 m above a 20 m building 50–60 m north: seen from above, its far roof edge stands
  // highest, at atan2(20 − 100, 60) = −53°; in bin 0 = [0°, 1°] at its far end, 60 m / cos 1°.
  const BuildingIndex index({building(box(-10, 50, 10, 60), 20.0)});
  const SkyMask m = computeSkyMask(eye(kGround, 100.0), &index, nullptr);
  // The mask places the walls at the eye's height: a wall's plumb line leans from the eye's
  // vertical by d/R, so the roof edge 80 m below is taken 80 m × 60 m / R = 0.75 mm farther out
  // — higher in angle when looking down (7.5e-6 rad here), on the safe side.
  const double d = 60.0 / std::cos(deg2rad(1.0));
  const double R = primeVertical_m(kGround.lat_rad);
  const double exact = std::atan2(20.0 - 100.0 - d * d / (2 * R), d);
  EXPECT_GE(m.binBlocked_rad(0), exact);
  EXPECT_NEAR(m.binBlocked_rad(0), exact, 80.0 * d / R / d * 1.1);
  EXPECT_EQ(m.binBlocked_rad(180), kOpenSky_rad);
}

// --- the indexed, culled mask against brute force on random cities --------------------------

struct City {
  std::vector<Building> buildings;
};

/// n random buildings (4–12 vertices, star-shaped so the footprint is simple) in a square of
/// `side_m`, heights 5–60 m.
City randomCity(std::mt19937& rng, int n, double side_m) {
  std::uniform_real_distribution<double> pos(-side_m / 2, side_m / 2), radius(4, 20), height(5, 60), jitter(0.6, 1.0);
  std::uniform_int_distribution<int> verts(4, 12);
  City c;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d centre(pos(rng), pos(rng));
    const int m = verts(rng);
    const double r = radius(rng);
    std::vector<Eigen::Vector2d> fp;
    for (int k = 0; k < m; ++k) {
      const double a = 2 * M_PI * k / m;
      fp.push_back(centre + r * jitter(rng) * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    c.buildings.push_back(building(fp, height(rng)));
  }
  return c;
}

/// Independent reference: rays at per_bin + 1 azimuths across each bin, both edges included
/// (the mask's wedge is closed: a building that only touches a bin at its edge shows there), each ray's crossings
/// with every footprint (footprints placed in the observer's own ENU frame at its height),
/// elevation with the drop. Returns the highest per bin.
std::vector<double> rayCastMask(const std::vector<Building>& buildings, const Geodetic& observer, int per_bin) {
  const LocalFrame at(observer);
  const double R = primeVertical_m(observer.lat_rad);
  std::vector<double> out(360, kOpenSky_rad);
  std::vector<std::vector<Eigen::Vector2d>> rings;
  for (const Building& b : buildings) {
    std::vector<Eigen::Vector2d> r;
    for (const auto& [lat, lon] : b.ring_lat_lon_rad) r.push_back(at.toEnu({lat, lon, observer.h_ell_m}).head<2>());
    rings.push_back(r);
  }
  for (int k = 0; k < 360; ++k) {
    for (int j = 0; j <= per_bin; ++j) {
      const double az = deg2rad(k + static_cast<double>(j) / per_bin);
      const Eigen::Vector2d u(std::sin(az), std::cos(az));
      for (std::size_t b = 0; b < rings.size(); ++b) {
        const double dh = buildings[b].top_h_ell_m - observer.h_ell_m;
        double& best = out[static_cast<std::size_t>(k)];
        for (std::size_t i = 0; i < rings[b].size(); ++i) {
          const Eigen::Vector2d p = rings[b][i], q = rings[b][(i + 1) % rings[b].size()];
          // Solve s·u = p + t·(q − p), s ≥ 0, t ∈ [0, 1], by Cramer's rule.
          const auto cross = [](const Eigen::Vector2d& v1, const Eigen::Vector2d& v2) { return v1.x() * v2.y() - v1.y() * v2.x(); };
          const double den = cross(u, q - p);
          if (std::abs(den) < 1e-12) continue;
          const Eigen::Vector2d st(cross(p, q - p) / den, cross(p, u) / den);
          // Every crossing: the nearest stands highest for a top above the eye, the farthest
          // for a top below it.
          if (st.x() >= 0 && st.y() >= 0 && st.y() <= 1) best = std::max(best, std::atan2(dh - st.x() * st.x() / (2 * R), st.x()));
        }
      }
    }
  }
  return out;
}

TEST(SkyMaskBuildings, CulledIndexEqualsBruteForceAndBoundsDenseRayCasting) {
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> where(-300, 300);
  for (int trial = 0; trial < 6; ++trial) {
    const City city = randomCity(rng, 400, 1200.0);
    const BuildingIndex index(city.buildings, kGround, trial % 2 ? 20.0 : 75.0);
    for (int q = 0; q < 4; ++q) {
      Geodetic p = LocalFrame(kGround).fromEnu({where(rng), where(rng), 0.0});
      p.h_ell_m = kGround.h_ell_m + (q == 3 ? 80.0 : kEye_m);  // street level, and a drone
      SkyMaskOptions fast, brute;
      brute.cull = false;
      const SkyMask a = computeSkyMask(p, &index, nullptr, fast);
      const SkyMask b = computeSkyMask(p, &index, nullptr, brute);
      SCOPED_TRACE("trial " + std::to_string(trial) + " query " + std::to_string(q));
      for (int k = 0; k < 360; ++k) ASSERT_EQ(a.binBlocked_rad(k), b.binBlocked_rad(k)) << "bin " << k;
      if (a.binBlocked_rad(0) == M_PI / 2) continue;  // inside a building
      const std::vector<double> rays = rayCastMask(city.buildings, p, 24);
      for (int k = 0; k < 360; ++k) {
        // No ray sees a building above the mask …
        EXPECT_LE(rays[static_cast<std::size_t>(k)], a.binBlocked_rad(k) + kAngleTol_rad) << "bin " << k;
        // … and the mask is no higher than what the rays just miss (closest points between rays).
        EXPECT_LE(a.binBlocked_rad(k) - rays[static_cast<std::size_t>(k)], deg2rad(0.5)) << "bin " << k;
      }
    }
  }
}

TEST(SkyMaskBuildings, AMastOneHundredFiftyKilometresAwayLeavesTheStreetMaskAsBruteForce) {
  // GIVEN a street block and, 150 km west, a 60 m mast: the fuzzer's slow input (the example's
  // mast with its longitude mistyped 6.54° for 8.54°), 3001 × 2 cells of 50 m here
  const double d = 50.0, H = 20.0, half_w = 10.0;
  const BuildingIndex index({building(box(-half_w, d, half_w, d + 10), H), building(box(-150000, 0, -149998, 2), 60.0)}, kGround);
  SkyMaskOptions brute;
  brute.cull = false;
  const SkyMask fast = computeSkyMask(eye(), &index, nullptr);
  const SkyMask slow = computeSkyMask(eye(), &index, nullptr, brute);
  // THEN the grid is within the budget of two buildings (see cells())
  EXPECT_LE(index.cells(), 3u * 4096u + 1u);
  // AND the culled walk over the long grid gives the brute-force mask
  for (int k = 0; k < 360; ++k) ASSERT_EQ(fast.binBlocked_rad(k), slow.binBlocked_rad(k)) << "bin " << k;
  // AND the block to the north shows as in ABoxToTheNorth…; the mast, 1.76 km below the
  // tangent plane at 150 km, is below the horizon, e = atan2(60 − 1.5 − d²/2R, d) < 0
  const double R = primeVertical_m(kGround.lat_rad);
  EXPECT_NEAR(fast.binBlocked_rad(0), std::atan2(H - kEye_m - d * d / (2 * R), d), kAngleTol_rad);
  const double far_m = 149999.0;
  EXPECT_NEAR(fast.binBlocked_rad(270), std::atan2(60.0 - kEye_m - far_m * far_m / (2 * R), far_m), 1e-5);
}

TEST(SkyMaskBuildings, AFewBuildingsFarApartGetAGridSizedByTheirCountNotTheirSpread) {
  // GIVEN the street block and a mast 150 km west and 100 km south: a 3000 × 2000 grid of
  // 50 m cells would span them (6e6 cells, 190 MB)
  const double d = 50.0, H = 20.0, half_w = 10.0;
  const BuildingIndex index({building(box(-half_w, d, half_w, d + 10), H), building(box(-150000, -100000, -149998, -99998), 60.0)},
                            kGround);
  // THEN the grid holds at most 3·4096 + 1 cells (the budget of a few buildings, see cells())
  EXPECT_LE(index.cells(), 3u * 4096u + 1u);
  // AND the coarse grid still culls exactly: the brute-force mask, the block's elevation
  SkyMaskOptions brute;
  brute.cull = false;
  const SkyMask fast = computeSkyMask(eye(), &index, nullptr);
  const SkyMask slow = computeSkyMask(eye(), &index, nullptr, brute);
  for (int k = 0; k < 360; ++k) ASSERT_EQ(fast.binBlocked_rad(k), slow.binBlocked_rad(k)) << "bin " << k;
  const double R = primeVertical_m(kGround.lat_rad);
  EXPECT_NEAR(fast.binBlocked_rad(0), std::atan2(H - kEye_m - d * d / (2 * R), d), kAngleTol_rad);
}

// A floor at the receiver's elevation mask: every bin is max(floor, the brute-force mask), from
// the street and from a drone above the roofs (where the floor lets the culling skip almost all).
TEST(SkyMaskBuildings, FloorGivesTheBruteForceMaskRaisedToTheFloor) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(-300, 300);
  const City city = randomCity(rng, 400, 1200.0);
  const BuildingIndex index(city.buildings, kGround, 50.0);
  for (int q = 0; q < 6; ++q) {
    Geodetic p = LocalFrame(kGround).fromEnu({where(rng), where(rng), 0.0});
    p.h_ell_m = kGround.h_ell_m + (q % 2 ? 80.0 : kEye_m);
    SkyMaskOptions floored, brute;
    floored.floor_rad = deg2rad(5.0);
    brute.cull = false;
    const SkyMask a = computeSkyMask(p, &index, nullptr, floored);
    const SkyMask b = computeSkyMask(p, &index, nullptr, brute);
    for (int k = 0; k < 360; ++k) {
      ASSERT_EQ(a.binBlocked_rad(k), std::max(deg2rad(5.0), b.binBlocked_rad(k))) << "query " << q << " bin " << k;
    }
  }
}

// --- terrain ----------------------------------------------------------------------------------

TEST(SkyMaskTerrain, FlatGroundGivesTheHorizonDipOfTheObserversHeight) {
  const Terrain flat = Terrain::flat(300.0);
  const double N = Geoid::egm96().undulation_m(kGround.lat_rad, kGround.lon_rad);
  const Geodetic drone{kGround.lat_rad, kGround.lon_rad, 300.0 + N + 100.0};
  SkyMaskOptions o;
  o.terrain_max_range_m = 50000;
  const SkyMask m = computeSkyMask(drone, nullptr, &flat, o);
  // The dip of the horizon from height h over a sphere: acos(R / (R + h)) ≈ √(2h/R).
  const double R = primeVertical_m(kGround.lat_rad);
  for (int k : {0, 90, 200, 359}) EXPECT_NEAR(m.binBlocked_rad(k), -std::acos(R / (R + 100.0)), 1e-5) << k;
  // Within 10 km the tangent point (35.7 km) is out of range: the 10 km ground point counts.
  o.terrain_max_range_m = 10000;
  EXPECT_NEAR(computeSkyMask(drone, nullptr, &flat, o).binBlocked_rad(7),
              std::atan2(-100.0 - 1e8 / (2 * R), 1e4), kAngleTol_rad);
  // Standing on the ground, the horizon is level; below it, everything is blocked.
  EXPECT_EQ(computeSkyMask({drone.lat_rad, drone.lon_rad, 300.0 + N}, nullptr, &flat, o).binBlocked_rad(3), 0.0);
  EXPECT_EQ(computeSkyMask({drone.lat_rad, drone.lon_rad, 290.0 + N}, nullptr, &flat, o).binBlocked_rad(3), M_PI / 2);
}

TEST(SkyMaskTerrain, ARidgeTwoKilometresNorthRaisesTheNorthernHorizon) {
  // GIVEN a DEM, 0 m everywhere but a 200 m high ridge between 1.8 and 2.4 km north
  const double lat0 = rad2deg(kGround.lat_rad), lon0 = rad2deg(kGround.lon_rad);
  const double cell_deg = 2e-4;  // 22 m north, 15 m east
  const double e2 = 6.69437999014e-3, s = std::sin(kGround.lat_rad);
  const double M = 6378137.0 * (1 - e2) / std::pow(1 - e2 * s * s, 1.5);  // meridian radius: m per radian of latitude
  const double gt[6] = {lon0 - 0.06, cell_deg, 0, lat0 + 0.04, 0, -cell_deg};
  const auto rowNorth_m = [&](int r) { return deg2rad(lat0 + 0.04 - (r + 0.5) * cell_deg - lat0) * M; };
  const std::string tif = test::writeGeoTiff("ridge.tif", 600, 400, gt, "EPSG:4326", [&](int r, int) {
    const double n = rowNorth_m(r);
    return (n >= 1800 && n <= 2400) ? 200.0 : 0.0;
  });
  const Terrain dem = Terrain::fromRaster(tif);
  ASSERT_TRUE(dem.cellSize_m().has_value());
  EXPECT_NEAR(*dem.cellSize_m(), 2e-4 * M_PI / 180 * 6378137.0 * std::cos(deg2rad(lat0)), 0.5);
  const double N = Geoid::egm96().undulation_m(kGround.lat_rad, kGround.lon_rad);
  const Geodetic observer{kGround.lat_rad, kGround.lon_rad, N + kEye_m};
  SkyMaskOptions o;
  o.terrain_max_range_m = 4000;
  const SkyMask m = computeSkyMask(observer, nullptr, &dem, o);
  // THEN bin 0 shows the ridge's near crest: atan2(200 − h − d²/2R, d) at d ≈ 1.8 km, to within
  // one step (a cell, ~15 m) of where the bilinear ramp reaches the crest (half a cell, 11 m).
  const double R = primeVertical_m(kGround.lat_rad);
  const auto e = [&](double dh, double d) { return std::atan2(dh - d * d / (2 * R), d); };
  // The first row of 200 m has its centre 0–22 m past 1.8 km; the bilinear ramp below it is
  // lower and farther in angle, so the highest sample lies between the crest at 1.8 km and
  // one row plus one step (15 m) beyond. The geoid's change to the crest is counted.
  const double d_crest = 1800.0;
  const Geodetic crest = LocalFrame(observer).fromEnu({0, d_crest, 0});
  const double dh_crest = 200.0 + Geoid::egm96().undulation_m(crest.lat_rad, crest.lon_rad) - observer.h_ell_m;
  EXPECT_LE(m.binBlocked_rad(0), e(dh_crest, d_crest) + 1e-6);
  EXPECT_GE(m.binBlocked_rad(0), e(dh_crest, d_crest + 23.0 + 16.0) - 1e-6);
  // AND at 45° the crest is 1.8 km / cos 45° away (the nearest of the bin's rays)
  EXPECT_NEAR(m.binBlocked_rad(45), e(dh_crest, (d_crest + 11.0) / std::cos(deg2rad(45.0))), deg2rad(0.1));
  // AND to the south the horizon is the flat ground's: just below level (dip of 1.5 m: 0.04°)
  EXPECT_LT(m.binBlocked_rad(180), 0.0);
  EXPECT_GT(m.binBlocked_rad(180), deg2rad(-0.06));
  // AND buildings and terrain combine by the maximum
  const BuildingIndex index({building(box(-10, 30, 10, 40), 15.0, {kGround.lat_rad, kGround.lon_rad, N})});
  const SkyMask both = computeSkyMask(observer, &index, &dem, o);
  EXPECT_NEAR(both.binBlocked_rad(0), e(15.0 - kEye_m, 30.0), kAngleTol_rad);
  EXPECT_EQ(both.binBlocked_rad(45), m.binBlocked_rad(45));
}

}  // namespace
}  // namespace skylane::maps
