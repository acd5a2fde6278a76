/// \file
/// \brief libFuzzer target for the corridor file and the fix record (geofence/corridor_file.hpp,
/// geofence/fix.hpp). Syntax errors are nlohmann's business and skipped. A document that parses
/// as a corridor file is built into both box levels (k out of range and a bad vehicle are
/// ParseErrors); then a protection volume of zero size at each waypoint that lies strictly
/// within the operating limits must be inside level 1 and level 2, and a volume twice as wide
/// as level 2 at the first waypoint must be outside both. A document that parses as a fix must
/// have finite values, PLs ≥ 0 and until ≥ time.

#include "fuzz/fuzz_common.hpp"
#include "geofence/corridor_file.hpp"
#include "geofence/fix.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void useBoxes(const geofence::CorridorSpec& spec) {
  const std::string source = spec.source;
  fuzz::parseThenUse(source, [&] { return geofence::buildBoxes(spec); }, [&](const geofence::CorridorBoxes& b) {
    const double val2 = b.limits.level2.val_m;
    for (const Eigen::Vector3d& w : b.level1.path()) {
      if (!(w.z() > spec.operating.floor_h_ell_m + 1e-6 && w.z() < spec.operating.ceiling_h_ell_m - 1e-6)) continue;
      const geofence::ProtectionVolume at_waypoint{w, 0.0, 0.0};
      SKYLANE_FUZZ_CHECK(b.level1.contains(at_waypoint, 1e-9).verdict != geofence::Verdict::kOutside, source);
      SKYLANE_FUZZ_CHECK(b.level2.contains(at_waypoint, 1e-9).verdict != geofence::Verdict::kOutside, source);
    }
    const geofence::ProtectionVolume huge{b.level1.path().front(), 2 * b.limits.level2.hal_m, 2 * val2};
    SKYLANE_FUZZ_CHECK(b.level1.contains(huge).verdict == geofence::Verdict::kOutside, source);
    SKYLANE_FUZZ_CHECK(b.level2.contains(huge).verdict == geofence::Verdict::kOutside, source);
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return 0;
  const std::string source = "fuzz.json";
  fuzz::parseThenUse(source, [&] { return geofence::parseCorridorSpec(doc, source); }, useBoxes);
  fuzz::parseThenUse(source, [&] { return geofence::parseFix(doc, source); }, [&](const geofence::Fix& f) {
    SKYLANE_FUZZ_CHECK(std::isfinite(f.lat_rad) && std::isfinite(f.lon_rad) && std::isfinite(f.h_ell_m), source);
    SKYLANE_FUZZ_CHECK(f.hpl_m >= 0 && f.vpl_m >= 0 && std::isfinite(f.hpl_m) && std::isfinite(f.vpl_m), source);
    SKYLANE_FUZZ_CHECK(f.t1 - f.t0 >= 0, source);
  });
  return 0;
}
