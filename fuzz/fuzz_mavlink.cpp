/// \file
/// \brief libFuzzer target for the MAVLink byte-stream parser (link/mavlink/wire.hpp). The input
/// is parsed twice: whole, and in chunks whose sizes the first byte chooses (a serial line or UDP
/// hands bytes over in any pieces). Both must give the same frames; every frame must be of a
/// known message with a length within its definition; written again with encodeFrame and parsed,
/// it must come back with the same id and payload; the parser's counters must add up.

#include "fuzz/fuzz_common.hpp"
#include "link/mavlink/wire.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

using namespace skylane::link::mavlink;

std::vector<Frame> parseInChunks(const std::uint8_t* data, std::size_t size, std::size_t chunk, FrameParser& parser) {
  std::vector<Frame> out;
  for (std::size_t at = 0; at < size; at += chunk) {
    parser.push(data + at, std::min(chunk, size - at));
    while (auto fr = parser.next()) out.push_back(*fr);
  }
  return out;
}

void checkFrame(const Frame& fr) {
  SKYLANE_FUZZ_CHECK(fr.def != nullptr && fr.def->id == fr.msgid, "a frame of a known message");
  SKYLANE_FUZZ_CHECK(fr.length <= fr.def->max_length, "a payload within its message's length");
  for (std::size_t i = fr.def->max_length; i < fr.payload.size(); ++i) SKYLANE_FUZZ_CHECK(fr.payload[i] == 0, "zero beyond the message");
  const std::vector<std::uint8_t> again = encodeFrame(*fr.def, fr.payload.data(), fr.seq, fr.sysid, fr.compid);
  FrameParser p;
  p.push(again.data(), again.size());
  const auto back = p.next();
  SKYLANE_FUZZ_CHECK(back && back->msgid == fr.msgid && back->payload == fr.payload, "a frame written again reads back");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t chunk = 1 + data[0] % 64;
  FrameParser whole, pieces;
  const std::vector<Frame> a = parseInChunks(data + 1, size - 1, size, whole);
  const std::vector<Frame> b = parseInChunks(data + 1, size - 1, chunk, pieces);
  SKYLANE_FUZZ_CHECK(a.size() == b.size(), "the same frames however the bytes arrive");
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    SKYLANE_FUZZ_CHECK(a[i].msgid == b[i].msgid && a[i].payload == b[i].payload && a[i].seq == b[i].seq, "the same frame");
    checkFrame(a[i]);
  }
  SKYLANE_FUZZ_CHECK(whole.stats().frames == a.size(), "every frame counted");
  SKYLANE_FUZZ_CHECK(whole.pending() <= size, "no more pending than given");
  return 0;
}
