/// \file
/// \brief libFuzzer target for the simulation scenario (integrity/sim/scenario.hpp). Syntax
/// errors are nlohmann's business and skipped. A scenario that parses must be flyable: its
/// trajectory builds without throwing, lasts a positive finite time and has finite truth at its
/// start, middle and end; every fault window is ordered on a valid axis with a finite size;
/// the rates are positive and orbit files are named. (No orbits are loaded.)

#include "fuzz/fuzz_common.hpp"
#include "integrity/sim/scenario.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace skylane;
  const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return 0;
  const std::string source = "fuzz.json";
  fuzz::parseThenUse(source, [&] { return integrity::sim::parseScenario(doc, source, "."); },
                     [&](const integrity::sim::Scenario& s) {
                       const integrity::sim::Trajectory t(s.origin, s.waypoints, s.turn_radius_m);
                       SKYLANE_FUZZ_CHECK(t.duration_s() > 0 && std::isfinite(t.duration_s()), source);
                       for (double at : {0.0, 0.5 * t.duration_s(), t.duration_s()}) {
                         const integrity::sim::TruthState x = t.at(at);
                         SKYLANE_FUZZ_CHECK(x.p_ecef_m.allFinite() && x.v_ecef_mps.allFinite(), source);
                         SKYLANE_FUZZ_CHECK(x.C_ecef_body.allFinite(), source);
                       }
                       for (const integrity::sim::FaultSpec& f : s.faults) {
                         SKYLANE_FUZZ_CHECK(f.t_end_s > f.t_start_s && f.axis >= 0 && f.axis < 3, source);
                         SKYLANE_FUZZ_CHECK(std::isfinite(f.magnitude), source);
                       }
                       SKYLANE_FUZZ_CHECK(s.sensors.imu.rate_hz > 0 && s.sensors.gnss_rate_hz > 0, source);
                       SKYLANE_FUZZ_CHECK(!s.orbit_files.empty(), source);
                     });
  return 0;
}
