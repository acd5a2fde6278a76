/// \file
/// \brief libFuzzer target for parseGeometry (integrity/geometry_file.hpp). The input is JSON
/// text; syntax errors are nlohmann's business and are skipped. A parsed geometry is then run
/// through buildGeometry, raimProtectionLevels (with the file's "raim" block) and
/// araimProtectionLevels (with its "araim" block and ISM): the PLs must be unavailable (with a
/// reason) or finite and >= 0, the optimised ARAIM PL never above the equal-allocation PL, and
/// nothing may throw — "integrity not available" is a result, not an error (STYLE.md).

#include "fuzz/fuzz_common.hpp"
#include "integrity/geometry_file.hpp"
#include "integrity/araim/mhss.hpp"
#include "integrity/raim/raim.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void exerciseGeometry(const integrity::GeometryInput& in) {
  for (const integrity::SatLook& s : in.satellites) {
    SKYLANE_FUZZ_CHECK(std::isfinite(s.look.azimuth_rad) && std::isfinite(s.look.elevation_rad), s.sat.str());
  }
  SKYLANE_FUZZ_CHECK(std::isfinite(in.tau_vert_m) && in.tau_vert_m >= 0.0, std::to_string(in.tau_vert_m));
  const integrity::Geometry g = integrity::buildGeometry(in.satellites, in.model, in.tau_vert_m);
  const integrity::RaimPl pl = integrity::raimProtectionLevels(g, in.raim);
  if (pl.available) {
    const std::string pls = "hpl " + std::to_string(pl.hpl_m) + " vpl " + std::to_string(pl.vpl_m);
    SKYLANE_FUZZ_CHECK(std::isfinite(pl.hpl_m) && pl.hpl_m >= 0.0, pls);
    SKYLANE_FUZZ_CHECK(std::isfinite(pl.vpl_m) && pl.vpl_m >= 0.0, pls);
  } else {
    SKYLANE_FUZZ_CHECK(!pl.reason.empty(), "unavailable PL without a reason");
  }
  const integrity::AraimResult a = integrity::araimProtectionLevels(g, in.model, in.araim);
  if (a.pl_computed) {
    const std::string pls = "araim hpl " + std::to_string(a.hpl_m) + " vpl " + std::to_string(a.vpl_m) +
                            " equal " + std::to_string(a.hpl_equal_allocation_m) + " " +
                            std::to_string(a.vpl_equal_allocation_m);
    SKYLANE_FUZZ_CHECK(std::isfinite(a.hpl_m) && a.hpl_m >= 0.0 && std::isfinite(a.vpl_m) && a.vpl_m >= 0.0, pls);
    SKYLANE_FUZZ_CHECK(std::isfinite(a.emt_m) && a.emt_m >= 0.0, "emt " + std::to_string(a.emt_m));
    // Bisection starts with the equal-allocation PL as its upper end and never raises it.
    const double tol = 1e-9 * (1.0 + a.hpl_equal_allocation_m + a.vpl_equal_allocation_m);
    SKYLANE_FUZZ_CHECK(a.hpl_m <= a.hpl_equal_allocation_m + tol, pls);
    if (!in.araim.horizontal_only) SKYLANE_FUZZ_CHECK(a.vpl_m <= a.vpl_equal_allocation_m + tol, pls);
  } else {
    SKYLANE_FUZZ_CHECK(!a.reason.empty(), "ARAIM PL not computed without a reason");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string kSource = "fuzz.json";
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return 0;
  fuzz::parseThenUse(kSource, [&] { return integrity::parseGeometry(doc, kSource); }, exerciseGeometry);
  return 0;
}
