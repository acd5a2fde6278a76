/// \file
/// \brief libFuzzer target for NMEA 0183 sentences and their assembly into fixes
/// (integrity/gnss/nmea.hpp). The input is split into lines; each line must parse or throw
/// ParseError naming its source; parsed sentences go through an assembler with a default date,
/// and every fix it releases must have finite coordinates within range and a finite height.

#include "fuzz/fuzz_common.hpp"
#include "integrity/gnss/nmea.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace skylane;
  const std::string text(reinterpret_cast<const char*>(data), size);
  integrity::NmeaEpochAssembler assembler(integrity::NmeaDate{{0.0}, 2026, 11, 23});
  auto check = [](const std::optional<integrity::NmeaFix>& f) {
    if (!f) return;
    SKYLANE_FUZZ_CHECK(std::abs(f->lat_rad) <= M_PI / 2 + 1e-12 && std::abs(f->lon_rad) <= M_PI + 1e-12, "fix in range");
    SKYLANE_FUZZ_CHECK(std::isfinite(f->h_ell_m) && std::isfinite(f->time.totalSeconds()), "fix finite");
  };
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    const std::string source = "fuzz.nmea:" + std::to_string(++n);
    fuzz::parseThenUse(source, [&] { return integrity::parseNmeaSentence(line, source); },
                       [&](const integrity::NmeaSentence& s) { check(assembler.add(s)); });
  }
  check(assembler.flush());
  return 0;
}
