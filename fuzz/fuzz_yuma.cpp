/// \file
/// \brief libFuzzer target for parseYuma (integrity/gnss/almanac.hpp): the input is the file text.

#include "fuzz/almanac_checks.hpp"
#include "integrity/gnss/almanac.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace skylane;
  static const std::string kSource = "fuzz.yuma";
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::parseThenUse(
      kSource, [&] { return integrity::parseYuma(text, kSource); },
      [](const std::vector<integrity::AlmanacRecord>& records) { fuzz::exerciseAlmanac(records); });
  return 0;
}
