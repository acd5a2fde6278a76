/// \file
/// \brief libFuzzer target for the UBX byte-stream parser and the NAV-PVT / NAV-PL decoders
/// (link/ubx/ubx.hpp), and the receiver-PL rule (link/ubx/fix_source.hpp). The input is parsed
/// whole and in chunks whose sizes the first byte chooses: the same frames both ways; a frame
/// written again with encode() reads back the same; a decoded NAV-PL gives PLs that are finite,
/// positive and not below the receiver's own, or a reason.

#include "fuzz/fuzz_common.hpp"
#include "link/ubx/fix_source.hpp"
#include "link/ubx/ubx.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

using namespace skylane::link::ubx;

std::vector<Frame> parse(const std::uint8_t* data, std::size_t size, std::size_t chunk) {
  FrameParser p;
  std::vector<Frame> out;
  for (std::size_t at = 0; at < size; at += chunk) {
    p.push(data + at, std::min(chunk, size - at));
    while (auto f = p.next()) out.push_back(*f);
  }
  return out;
}

void checkPl(const NavPl& pl) {
  const ReceiverPl r = receiverProtectionLevels(pl, {});
  if (!r.hpl_vpl_m) {
    SKYLANE_FUZZ_CHECK(!r.why_not.empty(), "an unusable NAV-PL says why");
    return;
  }
  const auto [hpl, vpl] = *r.hpl_vpl_m;
  SKYLANE_FUZZ_CHECK(std::isfinite(hpl) && std::isfinite(vpl) && hpl >= 0 && vpl >= 0, "finite PLs");
  SKYLANE_FUZZ_CHECK(vpl >= pl.pl_pos_mm[2] * 1e-3, "not below the receiver's vertical PL");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::vector<Frame> a = parse(data + 1, size - 1, size);
  const std::vector<Frame> b = parse(data + 1, size - 1, 1 + data[0] % 64);
  SKYLANE_FUZZ_CHECK(a.size() == b.size(), "the same frames however the bytes arrive");
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    SKYLANE_FUZZ_CHECK(a[i].cls == b[i].cls && a[i].id == b[i].id && a[i].payload == b[i].payload, "the same frame");
    const std::vector<std::uint8_t> again = encode(a[i].cls, a[i].id, a[i].payload);
    const std::vector<Frame> back = parse(again.data(), again.size(), again.size());
    SKYLANE_FUZZ_CHECK(back.size() == 1 && back[0].payload == a[i].payload, "a frame written again reads back");
    if (a[i].cls == kClassNav && a[i].id == kIdNavPl) {
      if (const auto pl = decodeNavPl(a[i].payload)) checkPl(*pl);
    }
    if (a[i].cls == kClassNav && a[i].id == kIdNavPvt) (void)decodeNavPvt(a[i].payload);
  }
  return 0;
}
