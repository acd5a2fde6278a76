#include "integrity/availability.hpp"

#include "integrity/predict.hpp"
#include "tests/test_util.hpp"

namespace skylane::integrity {
namespace {

OrbitSource gpsGalileo() {
  OrbitSource o;
  o.addAlmanac(loadAlmanac(test::dataPath("gnss/alm_gps_ed259.txt")));
  o.addAlmanac(loadAlmanac(test::dataPath("gnss/alm_gal_ed259.txt")));
  return o;
}

TEST(Availability, GridEpochCountsAndCellCentres) {
  AvailabilityRequest req;
  req.grid_deg = 30;
  req.start = *parseRfc3339("2017-01-01T00:00:00Z");
  req.duration_s = 7200;
  req.step_s = 600;
  const AvailabilityMap map = computeAvailability(gpsGalileo(), req);
  EXPECT_EQ(map.rows, 6);
  EXPECT_EQ(map.cols, 12);
  EXPECT_EQ(map.user_epochs, 6u * 12u * 12u);  // [start, start + 2 h) at 10 min
  EXPECT_DOUBLE_EQ(map.cells.front().lat_deg, -75.0);
  EXPECT_DOUBLE_EQ(map.cells.front().lon_deg, -165.0);
  for (const auto& c : map.cells) EXPECT_EQ(c.epochs, 12);
}

TEST(Availability, EveryCellAgreesWithThePerUserPrediction) {
  // The map's shared satellite positions (nominal 75 ms flight) against predict's per-user
  // light-time solution: the same available epochs at every cell.
  const OrbitSource orbits = gpsGalileo();
  AvailabilityRequest req;
  req.grid_deg = 45;
  req.start = *parseRfc3339("2017-01-01T06:00:00Z");
  req.duration_s = 3600;
  req.step_s = 900;
  req.threads = 2;
  const AvailabilityMap map = computeAvailability(orbits, req);
  for (const auto& c : map.cells) {
    PredictRequest p;
    p.place = {maps::deg2rad(c.lat_deg), maps::deg2rad(c.lon_deg), 0.0};
    p.start = req.start;
    p.duration_s = req.duration_s - req.step_s;  // predict includes its end point
    p.step_s = req.step_s;
    const auto samples = predictIntegrity(orbits, p, IntegrityMethod::kAraim);
    int available = 0;
    for (const auto& s : samples) available += s.pl.available;
    EXPECT_EQ(available, c.available) << c.lat_deg << ", " << c.lon_deg;
  }
}

TEST(Availability, OneThreadAndTwoThreadsGiveTheSameMap) {
  AvailabilityRequest req;
  req.grid_deg = 30;
  req.start = *parseRfc3339("2017-01-01T00:00:00Z");
  req.duration_s = 3600;
  req.step_s = 1200;
  req.threads = 1;
  const OrbitSource orbits = gpsGalileo();
  const AvailabilityMap a = computeAvailability(orbits, req);
  req.threads = 2;
  const AvailabilityMap b = computeAvailability(orbits, req);
  ASSERT_EQ(a.cells.size(), b.cells.size());
  for (std::size_t i = 0; i < a.cells.size(); ++i) {
    EXPECT_EQ(a.cells[i].available, b.cells[i].available);
    EXPECT_DOUBLE_EQ(a.cells[i].max_vpl_m, b.cells[i].max_vpl_m);
  }
}

}  // namespace
}  // namespace skylane::integrity
