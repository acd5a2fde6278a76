#pragma once
/// \file
/// \brief Checks shared by the YUMA and SEM targets: the record post-conditions parseYuma and
/// parseSem enforce (checkOrbit in almanac.cpp), then almanacState at a fixed epoch, as the CLI
/// evaluates an almanac at the user's time.

#include "fuzz/fuzz_common.hpp"
#include "integrity/gnss/almanac.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace skylane::fuzz {

/// \brief The epoch almanacs are evaluated at: 2024-06-24, GPS week 2320 (the rinex3 fixtures).
inline constexpr integrity::GpsTime kAlmanacEvalTime{2320, 115200.0};

/// \brief Checks every record and evaluates it; must not throw or trip a sanitizer.
inline void exerciseAlmanac(const std::vector<integrity::AlmanacRecord>& records) {
  SKYLANE_FUZZ_CHECK(!records.empty(), "a parsed almanac has at least one record");
  double sink = 0.0;
  for (const integrity::AlmanacRecord& r : records) {
    const std::string where = r.sat.str() + " line " + std::to_string(r.source_line);
    SKYLANE_FUZZ_CHECK(r.sat.prn >= 1 && r.sat.prn <= 99, where);
    SKYLANE_FUZZ_CHECK(r.orbit.e >= 0.0 && r.orbit.e < 1.0, where);
    SKYLANE_FUZZ_CHECK(r.orbit.sqrt_a > 1000.0 && r.orbit.sqrt_a < 10000.0, where);
    SKYLANE_FUZZ_CHECK(r.orbit.toe.sow >= 0.0 && r.orbit.toe.sow <= integrity::kSecondsPerWeek, where);
    SKYLANE_FUZZ_CHECK(r.orbit.constellation == r.sat.constellation, where);
    const integrity::SatelliteState s = integrity::almanacState(r, kAlmanacEvalTime);
    sink += s.p_ecef.sum() + s.clock_s;  // finiteness not required: only no crash, no UB
  }
  keepAlive(sink);
}

}  // namespace skylane::fuzz
