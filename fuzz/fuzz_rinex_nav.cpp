/// \file
/// \brief libFuzzer target for parseRinexNav (integrity/gnss/rinex_nav.hpp). After a successful
/// parse every record is checked against what the parser validates, selected with
/// selectEphemeris at its own toe (a healthy record must be found) and evaluated with
/// satelliteState; the data is merged into a copy.

#include "fuzz/fuzz_common.hpp"
#include "integrity/gnss/rinex_nav.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void exerciseNav(const integrity::NavigationData& nav) {
  using integrity::Constellation;
  double sink = 0.0;
  for (const integrity::BroadcastEphemeris& e : nav.ephemerides) {
    const std::string where = e.sat.str() + " line " + std::to_string(e.source_line);
    SKYLANE_FUZZ_CHECK(e.sat.constellation == Constellation::kGps || e.sat.constellation == Constellation::kGalileo,
                       where);
    SKYLANE_FUZZ_CHECK(e.sat.prn >= 1 && e.sat.prn <= 99, where);
    SKYLANE_FUZZ_CHECK(e.orbit.constellation == e.sat.constellation, where);
    SKYLANE_FUZZ_CHECK(e.orbit.e >= 0.0 && e.orbit.e < 1.0, where);
    SKYLANE_FUZZ_CHECK(e.orbit.sqrt_a > 1000.0 && e.orbit.sqrt_a < 10000.0, where);
    SKYLANE_FUZZ_CHECK(std::abs(e.orbit.toe - e.toc) <= integrity::kSecondsPerWeek / 2 + 1, where);

    const integrity::BroadcastEphemeris* chosen = integrity::selectEphemeris(nav, e.sat, e.orbit.toe);
    if (e.health == 0) SKYLANE_FUZZ_CHECK(chosen != nullptr, where + ": healthy record not selectable at its toe");
    if (chosen != nullptr) {
      const integrity::SatelliteState s = integrity::satelliteState(*chosen, e.orbit.toe);
      sink += s.p_ecef.sum() + s.clock_s;  // finiteness not required: only no crash, no UB
    }
    sink += integrity::satelliteState(e, e.toc).clock_s + integrity::clockPolynomial(e, e.toc);
  }
  integrity::NavigationData merged = nav;
  merged.merge(nav);
  SKYLANE_FUZZ_CHECK(merged.ephemerides.size() == 2 * nav.ephemerides.size(), "merge keeps every record");
  fuzz::keepAlive(sink);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string kSource = "fuzz.nav";
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::parseThenUse(kSource, [&] { return integrity::parseRinexNav(text, kSource); }, exerciseNav);
  return 0;
}
