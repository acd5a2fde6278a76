#pragma once
/// \file
/// \brief u-blox UBX on the wire (docs/vehicle_link.md §3), written from the u-blox interface
/// descriptions: frames 0xB5 0x62, class, id, a little-endian 16-bit length, the payload and an
/// 8-bit Fletcher checksum (CK_A, CK_B over class, id, length and payload); UBX-NAV-PVT
/// (0x01 0x07, 92 bytes) and UBX-NAV-PL (0x01 0x62, 52 bytes) decoded.

#include "link/byte_window.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace skylane::link::ubx {

/// \brief The checksum of `n` bytes (class to the payload's end): {CK_A, CK_B}.
[[nodiscard]] std::array<std::uint8_t, 2> fletcher8(const std::uint8_t* data, std::size_t n);

/// \brief A checked frame.
struct Frame {
  std::uint8_t cls = 0, id = 0;
  std::vector<std::uint8_t> payload;
};

struct ParserStats {
  std::uint64_t frames = 0;
  std::uint64_t bad_checksum = 0;   ///< start bytes dropped for a checksum that failed
  std::uint64_t too_long = 0;       ///< a length beyond kMaxPayload (start bytes dropped)
  std::uint64_t skipped_bytes = 0;  ///< bytes outside any frame
};

/// \brief The longest payload taken [bytes] (the messages read here are under 100; receivers'
/// longest, e.g. RXM-RAWX with many signals, a few kB).
constexpr std::size_t kMaxPayload = 8192;

/// \brief Splits a byte stream into checked frames of any class; garbage and bad checksums
/// are counted and skipped (the scan goes on at the next sync pair).
class FrameParser {
 public:
  void push(const std::uint8_t* data, std::size_t n) { window_.push(data, n); }
  [[nodiscard]] std::optional<Frame> next();
  [[nodiscard]] const ParserStats& stats() const { return stats_; }
  [[nodiscard]] std::size_t pending() const { return window_.pending(); }

 private:
  void drop(std::size_t n) { window_.drop(n); }
  ByteWindow window_;
  ParserStats stats_;
};

/// \brief One frame of class `cls`, id `id` with `payload`.
[[nodiscard]] std::vector<std::uint8_t> encode(std::uint8_t cls, std::uint8_t id, const std::vector<std::uint8_t>& payload);

constexpr std::uint8_t kClassNav = 0x01;
constexpr std::uint8_t kIdNavPvt = 0x07;
constexpr std::uint8_t kIdNavPl = 0x62;

/// \brief UBX-NAV-PVT: the navigation solution (the fields a fix needs).
struct NavPvt {
  std::uint32_t itow_ms = 0;
  std::uint16_t year = 0;
  std::uint8_t month = 0, day = 0, hour = 0, minute = 0, second = 0;
  std::uint8_t valid = 0;  ///< bit 0 validDate, bit 1 validTime, bit 2 fullyResolved
  std::int32_t nano_ns = 0;
  std::uint8_t fix_type = 0;  ///< 3: 3-D, 4: GNSS + dead reckoning
  std::uint8_t flags = 0;     ///< bit 0 gnssFixOK
  std::uint8_t num_sv = 0;
  std::int32_t lon_e7 = 0, lat_e7 = 0;
  std::int32_t height_mm = 0, hmsl_mm = 0;  ///< above the ellipsoid, above mean sea level
  std::uint32_t h_acc_mm = 0, v_acc_mm = 0;
};
/// \brief The NAV-PVT of a payload; none when it is not 92 bytes.
[[nodiscard]] std::optional<NavPvt> decodeNavPvt(const std::vector<std::uint8_t>& payload);

/// \brief UBX-NAV-PL: the receiver's protection levels, one per axis of `pos_frame`, each
/// bounding that axis's error with the target misleading-information risk
/// TMIR = tmir_coeff·10^tmir_exp [% per epoch].
struct NavPl {
  std::uint8_t version = 0;
  std::uint8_t tmir_coeff = 0;
  std::int8_t tmir_exp = 0;
  std::uint8_t pos_valid = 0;
  std::uint8_t pos_frame = 0;  ///< 0 invalid, 1 north-east-down, 2 longitudinal-lateral-vertical, 3 semi-major-semi-minor-vertical
  std::uint8_t pos_invalidity_reason = 0;
  std::uint32_t itow_ms = 0;
  std::array<std::uint32_t, 3> pl_pos_mm{};
  std::uint16_t pos_horizontal_orientation_cdeg = 0;
};
/// \brief The NAV-PL of a payload; none when it is not 52 bytes.
[[nodiscard]] std::optional<NavPl> decodeNavPl(const std::vector<std::uint8_t>& payload);

}  // namespace skylane::link::ubx
