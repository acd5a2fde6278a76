#include "link/ubx/ubx.hpp"

#include <algorithm>

namespace skylane::link::ubx {
namespace {

constexpr std::uint8_t kSync1 = 0xB5, kSync2 = 0x62;
constexpr std::size_t kHeader = 6;  ///< sync ×2, class, id, length ×2
constexpr std::size_t kNavPvtLength = 92, kNavPlLength = 52;

template <class T>
T read(const std::vector<std::uint8_t>& p, std::size_t at) {
  T v{};
  for (std::size_t k = 0; k < sizeof(T); ++k) reinterpret_cast<std::uint8_t*>(&v)[k] = p[at + k];  // little-endian host
  return v;
}

}  // namespace

std::array<std::uint8_t, 2> fletcher8(const std::uint8_t* data, std::size_t n) {
  std::uint8_t a = 0, b = 0;
  for (std::size_t i = 0; i < n; ++i) {
    a = static_cast<std::uint8_t>(a + data[i]);
    b = static_cast<std::uint8_t>(b + a);
  }
  return {a, b};
}

std::optional<Frame> FrameParser::next() {
  while (window_.start < window_.bytes.size()) {
    const auto begin = window_.bytes.begin() + static_cast<std::ptrdiff_t>(window_.start);
    const auto sync = std::find(begin, window_.bytes.end(), kSync1);
    const std::size_t garbage = static_cast<std::size_t>(sync - begin);
    stats_.skipped_bytes += garbage;
    drop(garbage);
    const std::size_t have = window_.bytes.size() - window_.start;
    if (have < 2) return std::nullopt;
    const std::uint8_t* b = window_.bytes.data() + window_.start;
    if (b[1] != kSync2) {
      ++stats_.skipped_bytes;
      drop(1);
      continue;
    }
    if (have < kHeader) return std::nullopt;
    const std::size_t len = b[4] | (b[5] << 8);
    if (len > kMaxPayload) {
      ++stats_.too_long;
      ++stats_.skipped_bytes;
      drop(1);
      continue;
    }
    if (have < kHeader + len + 2) return std::nullopt;
    const auto ck = fletcher8(b + 2, 4 + len);
    if (ck[0] != b[kHeader + len] || ck[1] != b[kHeader + len + 1]) {
      ++stats_.bad_checksum;
      ++stats_.skipped_bytes;
      drop(1);
      continue;
    }
    Frame f{b[2], b[3], std::vector<std::uint8_t>(b + kHeader, b + kHeader + len)};
    drop(kHeader + len + 2);
    ++stats_.frames;
    return f;
  }
  return std::nullopt;
}

std::vector<std::uint8_t> encode(std::uint8_t cls, std::uint8_t id, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out(kHeader + payload.size() + 2);
  out[0] = kSync1;
  out[1] = kSync2;
  out[2] = cls;
  out[3] = id;
  out[4] = static_cast<std::uint8_t>(payload.size() & 0xFF);
  out[5] = static_cast<std::uint8_t>(payload.size() >> 8);
  std::copy(payload.begin(), payload.end(), out.begin() + kHeader);
  const auto ck = fletcher8(out.data() + 2, 4 + payload.size());
  out[kHeader + payload.size()] = ck[0];
  out[kHeader + payload.size() + 1] = ck[1];
  return out;
}

std::optional<NavPvt> decodeNavPvt(const std::vector<std::uint8_t>& p) {
  if (p.size() != kNavPvtLength) return std::nullopt;
  NavPvt v;
  v.itow_ms = read<std::uint32_t>(p, 0);
  v.year = read<std::uint16_t>(p, 4);
  v.month = p[6];
  v.day = p[7];
  v.hour = p[8];
  v.minute = p[9];
  v.second = p[10];
  v.valid = p[11];
  v.nano_ns = read<std::int32_t>(p, 16);
  v.fix_type = p[20];
  v.flags = p[21];
  v.num_sv = p[23];
  v.lon_e7 = read<std::int32_t>(p, 24);
  v.lat_e7 = read<std::int32_t>(p, 28);
  v.height_mm = read<std::int32_t>(p, 32);
  v.hmsl_mm = read<std::int32_t>(p, 36);
  v.h_acc_mm = read<std::uint32_t>(p, 40);
  v.v_acc_mm = read<std::uint32_t>(p, 44);
  return v;
}

std::optional<NavPl> decodeNavPl(const std::vector<std::uint8_t>& p) {
  if (p.size() != kNavPlLength) return std::nullopt;
  NavPl v;
  v.version = p[0];
  v.tmir_coeff = p[1];
  v.tmir_exp = static_cast<std::int8_t>(p[2]);
  v.pos_valid = p[3];
  v.pos_frame = p[4];
  v.pos_invalidity_reason = p[8];
  v.itow_ms = read<std::uint32_t>(p, 12);
  for (std::size_t i = 0; i < 3; ++i) v.pl_pos_mm[i] = read<std::uint32_t>(p, 16 + 4 * i);
  v.pos_horizontal_orientation_cdeg = read<std::uint16_t>(p, 40);
  return v;
}

}  // namespace skylane::link::ubx
