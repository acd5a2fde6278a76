#include "link/mavlink/wire.hpp"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "MAVLink payloads are read and written as little-endian memory");

namespace skylane::link::mavlink {
namespace {

constexpr std::uint8_t kStartV2 = 0xFD;
constexpr std::uint8_t kStartV1 = 0xFE;
constexpr std::size_t kHeaderV2 = 10;  ///< start byte to the end of msgid
constexpr std::size_t kHeaderV1 = 6;
constexpr std::size_t kChecksum = 2;
constexpr std::size_t kSignature = 13;
constexpr std::uint8_t kIncompatSigned = 0x01;

std::uint16_t crcOfText(const std::string& text, std::uint16_t crc) {
  for (char c : text) crc = crcAccumulate(static_cast<std::uint8_t>(c), crc);
  return crc;
}

FieldDef f(const char* type, const char* name, int array_length = 0) { return {type, name, array_length, false, 0}; }

/// The messages skylane uses, field by field as the XML definitions declare them.
std::unordered_map<std::uint32_t, MessageDef> knownMessages() {
  std::vector<MessageDef> defs{
      // minimal.xml
      defineMessage(kHeartbeat, "HEARTBEAT",
                    {f("uint8_t", "type"), f("uint8_t", "autopilot"), f("uint8_t", "base_mode"), f("uint32_t", "custom_mode"),
                     f("uint8_t", "system_status"), f("uint8_t", "mavlink_version")},
                    {}),
      // standard.xml
      defineMessage(kGlobalPositionInt, "GLOBAL_POSITION_INT",
                    {f("uint32_t", "time_boot_ms"), f("int32_t", "lat"), f("int32_t", "lon"), f("int32_t", "alt"),
                     f("int32_t", "relative_alt"), f("int16_t", "vx"), f("int16_t", "vy"), f("int16_t", "vz"), f("uint16_t", "hdg")},
                    {}),
      // common.xml
      defineMessage(kGpsRawInt, "GPS_RAW_INT",
                    {f("uint64_t", "time_usec"), f("uint8_t", "fix_type"), f("int32_t", "lat"), f("int32_t", "lon"),
                     f("int32_t", "alt"), f("uint16_t", "eph"), f("uint16_t", "epv"), f("uint16_t", "vel"), f("uint16_t", "cog"),
                     f("uint8_t", "satellites_visible")},
                    {f("int32_t", "alt_ellipsoid"), f("uint32_t", "h_acc"), f("uint32_t", "v_acc"), f("uint32_t", "vel_acc"),
                     f("uint32_t", "hdg_acc"), f("uint16_t", "yaw")}),
      defineMessage(kGps2Raw, "GPS2_RAW",
                    {f("uint64_t", "time_usec"), f("uint8_t", "fix_type"), f("int32_t", "lat"), f("int32_t", "lon"),
                     f("int32_t", "alt"), f("uint16_t", "eph"), f("uint16_t", "epv"), f("uint16_t", "vel"), f("uint16_t", "cog"),
                     f("uint8_t", "satellites_visible"), f("uint8_t", "dgps_numch"), f("uint32_t", "dgps_age")},
                    {f("uint16_t", "yaw"), f("int32_t", "alt_ellipsoid"), f("uint32_t", "h_acc"), f("uint32_t", "v_acc"),
                     f("uint32_t", "vel_acc"), f("uint32_t", "hdg_acc")}),
      defineMessage(kMissionRequest, "MISSION_REQUEST",
                    {f("uint8_t", "target_system"), f("uint8_t", "target_component"), f("uint16_t", "seq")},
                    {f("uint8_t", "mission_type")}),
      defineMessage(kMissionCount, "MISSION_COUNT",
                    {f("uint8_t", "target_system"), f("uint8_t", "target_component"), f("uint16_t", "count")},
                    {f("uint8_t", "mission_type"), f("uint32_t", "opaque_id")}),
      defineMessage(kMissionAck, "MISSION_ACK",
                    {f("uint8_t", "target_system"), f("uint8_t", "target_component"), f("uint8_t", "type")},
                    {f("uint8_t", "mission_type"), f("uint32_t", "opaque_id")}),
      defineMessage(kMissionRequestInt, "MISSION_REQUEST_INT",
                    {f("uint8_t", "target_system"), f("uint8_t", "target_component"), f("uint16_t", "seq")},
                    {f("uint8_t", "mission_type")}),
      defineMessage(kMissionItemInt, "MISSION_ITEM_INT",
                    {f("uint8_t", "target_system"), f("uint8_t", "target_component"), f("uint16_t", "seq"), f("uint8_t", "frame"),
                     f("uint16_t", "command"), f("uint8_t", "current"), f("uint8_t", "autocontinue"), f("float", "param1"),
                     f("float", "param2"), f("float", "param3"), f("float", "param4"), f("int32_t", "x"), f("int32_t", "y"),
                     f("float", "z")},
                    {f("uint8_t", "mission_type")}),
  };
  std::unordered_map<std::uint32_t, MessageDef> out;
  for (MessageDef& d : defs) out.emplace(d.id, std::move(d));
  return out;
}

}  // namespace

std::uint16_t crcAccumulate(std::uint8_t byte, std::uint16_t crc) {
  std::uint8_t tmp = byte ^ static_cast<std::uint8_t>(crc & 0xFF);
  tmp = static_cast<std::uint8_t>(tmp ^ (tmp << 4));
  return static_cast<std::uint16_t>((crc >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
}

std::uint16_t crc16(const std::uint8_t* data, std::size_t n, std::uint16_t crc) {
  for (std::size_t i = 0; i < n; ++i) crc = crcAccumulate(data[i], crc);
  return crc;
}

int FieldDef::elementSize() const {
  if (type == "uint8_t" || type == "int8_t" || type == "char") return 1;
  if (type == "uint16_t" || type == "int16_t") return 2;
  if (type == "uint32_t" || type == "int32_t" || type == "float") return 4;
  if (type == "uint64_t" || type == "int64_t" || type == "double") return 8;
  throw std::invalid_argument("MAVLink field type " + type + " is not one of the wire types");
}

const FieldDef& MessageDef::field(std::string_view wanted) const {
  for (const FieldDef& x : fields) {
    if (x.name == wanted) return x;
  }
  throw std::out_of_range("MAVLink message " + name + " has no field " + std::string(wanted));
}

MessageDef defineMessage(std::uint32_t id, std::string name, std::vector<FieldDef> fields, std::vector<FieldDef> extensions) {
  MessageDef d;
  d.id = id;
  d.name = std::move(name);
  // Wire order: the base fields by element size, largest first, keeping declaration order among
  // equals; the extensions after them as declared.
  std::stable_sort(fields.begin(), fields.end(), [](const FieldDef& a, const FieldDef& b) { return a.elementSize() > b.elementSize(); });
  // CRC_EXTRA: the message name and each base field's type, name (and array length) in wire order.
  std::uint16_t crc = crcOfText(d.name + " ", 0xFFFF);
  int offset = 0;
  for (FieldDef& x : fields) {
    crc = crcOfText(x.type + " ", crc);
    crc = crcOfText(x.name + " ", crc);
    if (x.array_length > 0) crc = crcAccumulate(static_cast<std::uint8_t>(x.array_length), crc);
    x.offset = offset;
    offset += x.size();
  }
  d.min_length = offset;
  for (FieldDef& x : extensions) {
    x.extension = true;
    x.offset = offset;
    offset += x.size();
  }
  d.max_length = offset;
  d.crc_extra = static_cast<std::uint8_t>((crc & 0xFF) ^ (crc >> 8));
  d.fields = std::move(fields);
  d.fields.insert(d.fields.end(), extensions.begin(), extensions.end());
  return d;
}

const MessageDef* findMessage(std::uint32_t id) {
  static const std::unordered_map<std::uint32_t, MessageDef> known = knownMessages();
  const auto it = known.find(id);
  return it == known.end() ? nullptr : &it->second;
}

FrameParser::Step FrameParser::tryFrame(std::size_t at, Frame& out) {
  const std::uint8_t* b = window_.bytes.data() + at;
  const std::size_t have = window_.bytes.size() - at;
  const bool v2 = b[0] == kStartV2;
  const std::size_t header = v2 ? kHeaderV2 : kHeaderV1;
  if (have < header) return Step::kNeedMore;
  const std::uint8_t len = b[1];
  const std::uint8_t incompat = v2 ? b[2] : 0;
  if (incompat & ~kIncompatSigned) {  // a feature this parser does not know: not a frame it may read
    ++stats_.skipped_bytes;
    drop(1);
    return Step::kDropped;
  }
  const bool signed_frame = (incompat & kIncompatSigned) != 0;
  const std::size_t total = header + len + kChecksum + (signed_frame ? kSignature : 0);
  if (have < total) return Step::kNeedMore;
  const std::uint32_t msgid = v2 ? (b[7] | (b[8] << 8) | (static_cast<std::uint32_t>(b[9]) << 16)) : b[5];
  const MessageDef* def = findMessage(msgid);
  if (!def) {
    // Another dialect's message, or garbage that looks like a header: without its CRC_EXTRA the
    // checksum cannot tell them apart, so only the start byte is dropped and the scan goes on
    // (a real frame's payload is then passed over as skipped bytes).
    ++stats_.unknown_id;
    ++stats_.skipped_bytes;
    drop(1);
    return Step::kDropped;
  }
  const std::uint16_t sent = static_cast<std::uint16_t>(b[header + len] | (b[header + len + 1] << 8));
  const std::uint16_t crc = crcAccumulate(def->crc_extra, crc16(b + 1, header - 1 + len));
  if (len > def->max_length || crc != sent) {
    ++(len > def->max_length ? stats_.bad_length : stats_.bad_crc);
    ++stats_.skipped_bytes;
    drop(1);  // resynchronise on the next start byte
    return Step::kDropped;
  }
  out.v2 = v2;
  out.seq = v2 ? b[4] : b[2];
  out.sysid = v2 ? b[5] : b[3];
  out.compid = v2 ? b[6] : b[4];
  out.msgid = msgid;
  out.def = def;
  out.length = len;
  out.signed_frame = signed_frame;
  std::fill(out.payload.begin(), out.payload.end(), 0);
  std::copy(b + header, b + header + len, out.payload.begin());
  ++stats_.frames;
  drop(total);
  return Step::kFrame;
}

std::optional<Frame> FrameParser::next() {
  Frame frame;
  while (window_.start < window_.bytes.size()) {
    const auto begin = window_.bytes.begin() + static_cast<std::ptrdiff_t>(window_.start);
    const auto sync = std::find_if(begin, window_.bytes.end(), [](std::uint8_t c) { return c == kStartV2 || c == kStartV1; });
    const std::size_t garbage = static_cast<std::size_t>(sync - begin);
    stats_.skipped_bytes += garbage;
    drop(garbage);
    if (window_.start >= window_.bytes.size()) break;
    const Step s = tryFrame(window_.start, frame);
    if (s == Step::kFrame) return frame;
    if (s == Step::kNeedMore) return std::nullopt;
  }
  return std::nullopt;
}

std::vector<std::uint8_t> encodeFrame(const MessageDef& def, const std::uint8_t* payload, std::uint8_t seq, std::uint8_t sysid,
                                      std::uint8_t compid) {
  std::size_t len = static_cast<std::size_t>(def.max_length);
  while (len > 1 && payload[len - 1] == 0) --len;  // MAVLink 2: trailing zero bytes are not sent
  std::vector<std::uint8_t> out(kHeaderV2 + len + kChecksum);
  const std::uint8_t header[kHeaderV2] = {kStartV2, static_cast<std::uint8_t>(len), 0, 0, seq, sysid, compid,
                                          static_cast<std::uint8_t>(def.id & 0xFF), static_cast<std::uint8_t>((def.id >> 8) & 0xFF),
                                          static_cast<std::uint8_t>((def.id >> 16) & 0xFF)};
  std::copy(header, header + kHeaderV2, out.begin());
  std::copy(payload, payload + len, out.begin() + kHeaderV2);
  const std::uint16_t crc = crcAccumulate(def.crc_extra, crc16(out.data() + 1, kHeaderV2 - 1 + len));
  out[kHeaderV2 + len] = static_cast<std::uint8_t>(crc & 0xFF);
  out[kHeaderV2 + len + 1] = static_cast<std::uint8_t>(crc >> 8);
  return out;
}

}  // namespace skylane::link::mavlink
