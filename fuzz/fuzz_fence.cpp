/// \file
/// \brief libFuzzer target for the corridor file and the fix record (geofence/corridor_file.hpp,
/// geofence/fix.hpp). Syntax errors are nlohmann's business and skipped. A document that parses
/// as a corridor file is built into both box levels (k out of range and a bad vehicle are
/// ParseErrors); then a protection volume of zero size at each waypoint that lies strictly
/// within the operating limits must be inside level 1 and level 2, and a volume twice as wide
/// as level 2 at the first waypoint must be outside both. A document that parses as a fix must
/// have finite values, PLs ≥ 0 and until ≥ time. Whatever the fast reader of `fence check`
/// (geofence/fix_line.hpp) takes as a plain fix line must parse as JSON, pass parseFix and read
/// the same values, and its id text must be what nlohmann writes for the id.

#include "fuzz/fuzz_common.hpp"
#include "geofence/corridor_file.hpp"
#include "geofence/fix.hpp"
#include "geofence/fix_line.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

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

/// The fast reader's plain fix against parseFix of the same bytes.
void comparePlainFix(const std::uint8_t* data, std::size_t size, const nlohmann::json& doc, const std::string& source) {
  geofence::PlainFix p;
  if (!geofence::readPlainFixLine(std::string_view(reinterpret_cast<const char*>(data), size), p)) return;
  SKYLANE_FUZZ_CHECK(!doc.is_discarded(), source);
  geofence::Fix f;
  try {
    f = geofence::parseFix(doc, source);
  } catch (const std::exception& e) {
    ::skylane::fuzz::fail("parseFix refused a plain fix line", e.what());
  }
  SKYLANE_FUZZ_CHECK(p.id_json == (f.id.is_null() ? std::string() : f.id.dump()), source);
  SKYLANE_FUZZ_CHECK(p.t0.totalSeconds() == f.t0.totalSeconds() && p.t1.totalSeconds() == f.t1.totalSeconds(), source);
  SKYLANE_FUZZ_CHECK(p.lat_rad == f.lat_rad && p.lon_rad == f.lon_rad && p.h_ell_m == f.h_ell_m, source);
  SKYLANE_FUZZ_CHECK(p.hpl_m == f.hpl_m && p.vpl_m == f.vpl_m, source);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  const std::string source = "fuzz.json";
  comparePlainFix(data, size, doc, source);
  if (doc.is_discarded()) return 0;
  fuzz::parseThenUse(source, [&] { return geofence::parseCorridorSpec(doc, source); }, useBoxes);
  fuzz::parseThenUse(source, [&] { return geofence::parseFix(doc, source); }, [&](const geofence::Fix& f) {
    SKYLANE_FUZZ_CHECK(std::isfinite(f.lat_rad) && std::isfinite(f.lon_rad) && std::isfinite(f.h_ell_m), source);
    SKYLANE_FUZZ_CHECK(f.hpl_m >= 0 && f.vpl_m >= 0 && std::isfinite(f.hpl_m) && std::isfinite(f.vpl_m), source);
    SKYLANE_FUZZ_CHECK(f.t1 - f.t0 >= 0, source);
  });
  return 0;
}
