#pragma once
/// \file
/// \brief MAVLink 2 on the wire (docs/vehicle_link.md §2): the message definitions skylane uses,
/// taken field by field from the published XML definitions (minimal.xml, standard.xml,
/// common.xml of the MAVLink project), their wire layout and CRC_EXTRA derived from those field
/// lists as the MAVLink serialisation rules say, the CRC-16/MCRF4XX checksum, a frame encoder
/// and a byte-stream parser that resynchronises after garbage.
///
/// Frame (v2): 0xFD, len, incompat_flags, compat_flags, seq, sysid, compid, msgid (3 bytes,
/// little-endian), payload (len bytes, trailing zero bytes truncated by the sender), checksum
/// (2 bytes, CRC over everything after the start byte, then CRC_EXTRA), and a 13-byte signature
/// when incompat_flags has bit 0. Frame (v1): 0xFE, len, seq, sysid, compid, msgid (1 byte),
/// payload, checksum. Multi-byte fields are little-endian.

#include "link/byte_window.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::link::mavlink {

/// \brief One step of CRC-16/MCRF4XX (the X.25 CRC MAVLink uses; initial value 0xFFFF).
[[nodiscard]] std::uint16_t crcAccumulate(std::uint8_t byte, std::uint16_t crc);
/// \brief CRC-16/MCRF4XX of `n` bytes, from `crc`.
[[nodiscard]] std::uint16_t crc16(const std::uint8_t* data, std::size_t n, std::uint16_t crc = 0xFFFF);

/// \brief A field of a message, as its XML definition gives it.
struct FieldDef {
  std::string type;       ///< "uint8_t" … "double", "char"; uint8_t_mavlink_version counts as uint8_t
  std::string name;
  int array_length = 0;   ///< 0: not an array
  bool extension = false; ///< declared after <extensions/>
  int offset = 0;         ///< in the payload (wire order)
  /// \brief Bytes of one element.
  [[nodiscard]] int elementSize() const;
  /// \brief Bytes of the whole field.
  [[nodiscard]] int size() const { return elementSize() * (array_length > 0 ? array_length : 1); }
};

/// \brief A message: its fields in wire order, CRC_EXTRA and payload lengths.
struct MessageDef {
  std::uint32_t id = 0;
  std::string name;
  std::vector<FieldDef> fields;  ///< wire order: base fields by element size (largest first, stable), then extensions
  std::uint8_t crc_extra = 0;
  int min_length = 0;            ///< payload of the base fields (MAVLink 1)
  int max_length = 0;            ///< with the extensions
  /// \brief The field called `name`. \throws std::out_of_range when there is none.
  [[nodiscard]] const FieldDef& field(std::string_view name) const;
};

/// \brief A message definition from its XML field list (in declaration order; `extensions` are
/// those declared after <extensions/>): wire order, offsets, CRC_EXTRA, lengths.
[[nodiscard]] MessageDef defineMessage(std::uint32_t id, std::string name, std::vector<FieldDef> fields,
                                       std::vector<FieldDef> extensions);

/// \brief The definition of message `id`, or nullptr when skylane does not know it.
[[nodiscard]] const MessageDef* findMessage(std::uint32_t id);

/// \brief Message ids skylane speaks.
enum MessageId : std::uint32_t {
  kHeartbeat = 0,
  kGpsRawInt = 24,
  kGlobalPositionInt = 33,
  kMissionRequest = 40,
  kMissionCount = 44,
  kMissionAck = 47,
  kMissionRequestInt = 51,
  kMissionItemInt = 73,
  kGps2Raw = 124,
};

/// \brief A checked frame: header fields and the payload zero-extended to the message's length.
struct Frame {
  bool v2 = true;
  std::uint8_t seq = 0;
  std::uint8_t sysid = 0;
  std::uint8_t compid = 0;
  std::uint32_t msgid = 0;
  const MessageDef* def = nullptr;
  std::array<std::uint8_t, 256> payload{};  ///< zero beyond the bytes sent (MAVLink 2 truncation)
  std::uint8_t length = 0;                  ///< bytes sent
  bool signed_frame = false;                ///< carried a signature (not verified)

  /// \brief Field `f` as a T (little-endian), element `i` of an array.
  template <class T>
  [[nodiscard]] T get(const FieldDef& f, int i = 0) const {
    T v{};
    std::uint8_t* out = reinterpret_cast<std::uint8_t*>(&v);
    const int at = f.offset + i * static_cast<int>(sizeof(T));
    for (std::size_t k = 0; k < sizeof(T); ++k) out[k] = payload[static_cast<std::size_t>(at) + k];  // little-endian host
    return v;
  }
};

/// \brief What a parser has seen.
struct ParserStats {
  std::uint64_t frames = 0;        ///< checked and returned
  std::uint64_t bad_crc = 0;       ///< a known message whose checksum failed (its start byte dropped)
  std::uint64_t bad_length = 0;    ///< longer than the message can be (start byte dropped)
  std::uint64_t unknown_id = 0;    ///< a header with a message id skylane does not know (start byte dropped)
  std::uint64_t skipped_bytes = 0; ///< bytes outside any frame (garbage, dropped start bytes)
};

/// \brief Splits a byte stream into checked frames. Garbage, truncated frames and bad
/// checksums are counted and skipped; parsing goes on with the next start byte.
class FrameParser {
 public:
  /// \brief Appends bytes; frames are taken with next().
  void push(const std::uint8_t* data, std::size_t n) { window_.push(data, n); }
  /// \brief The next complete, checked frame of a known message, if any.
  [[nodiscard]] std::optional<Frame> next();
  [[nodiscard]] const ParserStats& stats() const { return stats_; }
  /// \brief Bytes waiting for the rest of a frame.
  [[nodiscard]] std::size_t pending() const { return window_.pending(); }

 private:
  enum class Step { kFrame, kNeedMore, kDropped };
  Step tryFrame(std::size_t at, Frame& out);
  void drop(std::size_t n) { window_.drop(n); }
  ByteWindow window_;
  ParserStats stats_;
};

/// \brief One MAVLink 2 frame of message `def` with `payload` (def.max_length bytes; trailing
/// zeros are truncated, at least one byte is sent), unsigned.
[[nodiscard]] std::vector<std::uint8_t> encodeFrame(const MessageDef& def, const std::uint8_t* payload, std::uint8_t seq,
                                                    std::uint8_t sysid, std::uint8_t compid);

/// \brief Builds a payload field by field (little-endian).
class PayloadWriter {
 public:
  explicit PayloadWriter(const MessageDef& def) : def_(def) {}
  template <class T>
  PayloadWriter& set(std::string_view name, T value, int i = 0) {
    const FieldDef& f = def_.field(name);
    const std::uint8_t* in = reinterpret_cast<const std::uint8_t*>(&value);
    const int at = f.offset + i * static_cast<int>(sizeof(T));
    for (std::size_t k = 0; k < sizeof(T); ++k) bytes_[static_cast<std::size_t>(at) + k] = in[k];
    return *this;
  }
  [[nodiscard]] const std::uint8_t* data() const { return bytes_.data(); }
  [[nodiscard]] const MessageDef& def() const { return def_; }

 private:
  const MessageDef& def_;
  std::array<std::uint8_t, 256> bytes_{};
};

}  // namespace skylane::link::mavlink
