/// \file
/// \brief libFuzzer target for parseRinexObs (integrity/gnss/rinex_obs.hpp). After a successful
/// parse every epoch and observation is visited: values aligned with the system's types,
/// epoch flags 0 or 1, the type lookup used by SPP, and the epoch time formatted as RFC 3339.

#include "fuzz/fuzz_common.hpp"
#include "integrity/gnss/rinex_obs.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace {

using namespace skylane;

void exerciseObs(const integrity::ObservationData& obs) {
  double sink = obs.interval_s;
  if (obs.approx_position_ecef) sink += obs.approx_position_ecef->sum();
  for (const integrity::Constellation c : integrity::kAllConstellations) {
    const auto& types = obs.types[static_cast<int>(c)];
    for (const integrity::ObsCode& code : types) sink += code.band + code.as_written.size();
    sink += integrity::findObsType(types, 'C', 1, "CWPX") + integrity::findObsType(types, 'L', 2) +
            integrity::findObsType(types, 'C', 5, "QIX");
  }
  for (const integrity::ObservationEpoch& ep : obs.epochs) {
    const std::string where = "epoch at line " + std::to_string(ep.source_line);
    SKYLANE_FUZZ_CHECK(ep.flag == 0 || ep.flag == 1, where);
    SKYLANE_FUZZ_CHECK(std::isfinite(ep.t.sow), where);
    sink += integrity::formatRfc3339(ep.t, 3).size();
    for (const integrity::SatObservation& so : ep.sats) {
      const auto& types = obs.types[static_cast<int>(so.sat.constellation)];
      SKYLANE_FUZZ_CHECK(so.values.size() == types.size(),
                         where + " " + so.sat.str() + ": " + std::to_string(so.values.size()) + " values for " +
                             std::to_string(types.size()) + " types");
      SKYLANE_FUZZ_CHECK(so.sat.prn >= 1, where);
      for (const double v : so.values) {
        if (!std::isnan(v)) sink += v;
      }
    }
  }
  fuzz::keepAlive(sink);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string kSource = "fuzz.obs";
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::parseThenUse(kSource, [&] { return integrity::parseRinexObs(text, kSource); }, exerciseObs);
  return 0;
}
