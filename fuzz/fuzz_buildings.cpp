/// \file
/// \brief libFuzzer target for the buildings loader (maps/buildings.hpp) and what is built on
/// its result: prisms, meshes and the sky mask. Syntax errors are nlohmann's business and
/// skipped. Every building parsed must have ≥ 3 finite vertices and a top above its base; its
/// prism's mesh must have 2n vertices and 4n − 4 triangles with indices in range; the sky mask
/// at the first building's first corner and 50 m off it must hold finite angles in [−90°, 90°],
/// and equal the brute-force mask.

#include "fuzz/fuzz_common.hpp"
#include "maps/buildings.hpp"
#include "maps/sky_mask.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void exercise(const std::vector<maps::Building>& buildings) {
  if (buildings.empty()) return;
  const auto& [lat0, lon0] = buildings.front().ring_lat_lon_rad.front();
  const maps::Geodetic origin{lat0, lon0, buildings.front().base_h_ell_m};
  const maps::LocalFrame frame(origin);
  for (const maps::Building& b : buildings) {
    const std::size_t n = b.ring_lat_lon_rad.size();
    SKYLANE_FUZZ_CHECK(n >= 3, b.feature);
    SKYLANE_FUZZ_CHECK(b.top_h_ell_m > b.base_h_ell_m, b.feature);
    for (const auto& [lat, lon] : b.ring_lat_lon_rad) SKYLANE_FUZZ_CHECK(std::isfinite(lat) && std::isfinite(lon), b.feature);
    const maps::Prism p = maps::extrude(b, frame);
    SKYLANE_FUZZ_CHECK(p.top_u_m > p.bottom_u_m, b.feature);
    const maps::TriangleMesh m = maps::prismMesh(p);
    SKYLANE_FUZZ_CHECK(m.vertices_enu.size() == 2 * n && m.triangles.size() == 4 * n - 4, b.feature);
    for (const auto& t : m.triangles) {
      for (int i : t) SKYLANE_FUZZ_CHECK(i >= 0 && static_cast<std::size_t>(i) < 2 * n, b.feature);
    }
  }
  const maps::BuildingIndex index(buildings, origin);
  maps::SkyMaskOptions brute;
  brute.cull = false;
  for (const double offset_m : {0.0, 50.0}) {
    maps::Geodetic p = frame.fromEnu({offset_m, offset_m, 1.5});
    const maps::SkyMask fast = maps::computeSkyMask(p, &index, nullptr);
    const maps::SkyMask slow = maps::computeSkyMask(p, &index, nullptr, brute);
    for (int k = 0; k < fast.bins(); ++k) {
      const double e = fast.binBlocked_rad(k);
      SKYLANE_FUZZ_CHECK(std::isfinite(e) && std::abs(e) <= M_PI / 2, std::to_string(e));
      SKYLANE_FUZZ_CHECK(e == slow.binBlocked_rad(k), "bin " + std::to_string(k) + ": culled " + std::to_string(e) +
                                                          " vs brute force " + std::to_string(slow.binBlocked_rad(k)));
    }
    fuzz::keepAlive(fast.binBlocked_rad(0));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string kSource = "fuzz.geojson";
  static const maps::Terrain kFlat = maps::Terrain::flat(100.0);
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return 0;
  fuzz::parseThenUse(kSource, [&] { return maps::parseBuildings(doc, kSource, kFlat); }, exercise);
  return 0;
}
