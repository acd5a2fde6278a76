#include "geofence/verdict_writer.hpp"

#include "maps/decimal_text.hpp"
#include "maps/json_numbers.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace skylane::geofence {

namespace detail {

/// Writes into space sized beforehand (VerdictLineWriter::append sizes it): one pointer moves
/// on, with no capacity check per piece of text.
class TextCursor {
 public:
  explicit TextCursor(char* at) : at_(at) {}
  template <std::size_t N>
  void literal(const char (&text)[N]) {
    std::memcpy(at_, text, N - 1);
    at_ += N - 1;
  }
  void text(std::string_view t) {
    std::memcpy(at_, t.data(), t.size());
    at_ += t.size();
  }
  void put(char c) { *at_++ = c; }
  /// Where the next byte goes; advance(end) after writing there.
  [[nodiscard]] char* at() const { return at_; }
  void advance(char* end) { at_ = end; }

 private:
  char* at_;
};

}  // namespace detail

namespace {

using Cursor = detail::TextCursor;

/// maps::metresOrNull as its JSON text (at most maps::kRoundedMaxChars).
void putMetres(Cursor& out, double v) {
  if (!std::isfinite(v)) {
    out.literal("null");
    return;
  }
  out.advance(maps::jsonTextOfMillimetres(out.at(), maps::roundToMm(v)));
}

void putUnsigned(Cursor& out, std::size_t v) {
  out.advance(std::to_chars(out.at(), out.at() + 24, v).ptr);
}

/// Length of the UTF-8 sequence starting at s[i] (Unicode 15 §3.9, Table 3-7: no overlong
/// forms, no surrogates, ≤ U+10FFFF — what nlohmann's decoder accepts); 0 when invalid.
std::size_t utf8Length(std::string_view s, std::size_t i) {
  const auto at = [&](std::size_t k) { return i + k < s.size() ? static_cast<unsigned char>(s[i + k]) : 0u; };
  const auto cont = [&](std::size_t k, unsigned lo = 0x80, unsigned hi = 0xBF) { return at(k) >= lo && at(k) <= hi; };
  const unsigned b = at(0);
  if (b >= 0xC2 && b <= 0xDF) return cont(1) ? 2 : 0;
  if (b == 0xE0) return cont(1, 0xA0) && cont(2) ? 3 : 0;
  if ((b >= 0xE1 && b <= 0xEC) || b == 0xEE || b == 0xEF) return cont(1) && cont(2) ? 3 : 0;
  if (b == 0xED) return cont(1, 0x80, 0x9F) && cont(2) ? 3 : 0;
  if (b == 0xF0) return cont(1, 0x90) && cont(2) && cont(3) ? 4 : 0;
  if (b >= 0xF1 && b <= 0xF3) return cont(1) && cont(2) && cont(3) ? 4 : 0;
  if (b == 0xF4) return cont(1, 0x80, 0x8F) && cont(2) && cont(3) ? 4 : 0;
  return 0;
}

/// Whether c goes into a JSON string as it is (printable ASCII other than '"' and '\\').
bool plainAscii(unsigned char c) { return c >= 0x20 && c < 0x80 && c != '"' && c != '\\'; }

/// Writes the escaped form of c (a control character, '"' or '\\'), as nlohmann writes it: at most
/// 6 bytes.
void putEscape(Cursor& out, unsigned char c) {
  static constexpr char kHex[] = "0123456789abcdef";
  switch (c) {
    case '\b': out.literal("\\b"); return;
    case '\t': out.literal("\\t"); return;
    case '\n': out.literal("\\n"); return;
    case '\f': out.literal("\\f"); return;
    case '\r': out.literal("\\r"); return;
    case '"': out.literal("\\\""); return;
    case '\\': out.literal("\\\\"); return;
    default: {
      const char esc[] = {'\\', 'u', '0', '0', kHex[c >> 4], kHex[c & 15]};
      out.text({esc, sizeof esc});
    }
  }
}

/// A JSON string as nlohmann's dump(-1) writes it (ensure_ascii off: UTF-8 as it is; \b \t \n
/// \f \r \" \\ and \u00xx for the other control characters), at most 6 bytes per byte of s
/// and 2 quotes; false on invalid UTF-8. Runs of plain characters are copied whole.
bool putString(Cursor& out, std::string_view s) {
  out.put('"');
  for (std::size_t i = 0; i < s.size();) {
    std::size_t run = i;
    while (run < s.size() && plainAscii(static_cast<unsigned char>(s[run]))) ++run;
    out.text(s.substr(i, run - i));
    if (run == s.size()) break;
    i = run;
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      putEscape(out, c);
      ++i;
      continue;
    }
    const std::size_t n = utf8Length(s, i);
    if (n == 0) return false;
    out.text(s.substr(i, n));
    i += n;
  }
  out.put('"');
  return true;
}

/// A word of the format (a level, a verdict: plain lower-case ASCII) as a JSON string.
void putWord(Cursor& out, std::string_view word) {
  out.put('"');
  out.text(word);
  out.put('"');
}

/// Most bytes putString writes for s.
std::size_t stringBound(std::string_view s) { return 6 * s.size() + 2; }

/// A time as the line writes it: formatRfc3339To's text, or formatRfc3339's for the times it
/// leaves to it.
class TimeText {
 public:
  explicit TimeText(const maps::GpsTime& t) {
    if (const char* end = maps::formatRfc3339To(buf_, t, 3)) {
      view_ = {buf_, static_cast<std::size_t>(end - buf_)};
    } else {
      slow_ = maps::formatRfc3339(t, 3);
      view_ = slow_;
    }
  }
  [[nodiscard]] std::string_view view() const { return view_; }

 private:
  char buf_[maps::kRfc3339MaxChars];
  std::string slow_;
  std::string_view view_;
};

/// Bytes of a check's text other than its strings, millimetre numbers and file: its keys,
/// punctuation, level and verdict words and segment number come to at most ≈ 190 (a box check:
/// 20 digits of segment, "indeterminate").
constexpr std::size_t kCheckFixedBytes = 256;
/// Bytes of a line other than its checks, id and times: at most ≈ 130 (20 digits of line
/// number, "indeterminate", "keep_in").
constexpr std::size_t kLineFixedBytes = 256;

/// Text made once (the constructor's): written into a string with room for it.
template <typename Write>
std::string textOf(std::size_t bound, Write write) {
  std::string text(bound, '\0');
  Cursor out(text.data());
  write(out);
  text.resize(static_cast<std::size_t>(out.at() - text.data()));
  return text;
}

}  // namespace

VerdictLineWriter::VerdictLineWriter(const Fence& fence) {
  for (const Corridor* level : {&fence.level1(), &fence.level2()}) {
    const auto metres = [](double v) { return textOf(maps::kRoundedMaxChars, [&](Cursor& out) { putMetres(out, v); }); };
    limits_text_.push_back({metres(level->limits().hal_m), metres(level->limits().val_m)});
  }
  for (const airspace::Zone& z : fence.zones()) {
    bool ok = true;
    zone_files_.push_back(textOf(stringBound(z.source), [&](Cursor& out) { ok = putString(out, z.source); }));
    zone_file_ok_.push_back(ok);
  }
}

std::size_t VerdictLineWriter::checkBound(const Check& c) const {
  const bool zone = c.level == Level::kZone || c.level == Level::kKeepIn;
  return kCheckFixedBytes + 5 * maps::kRoundedMaxChars + stringBound(c.subject) + stringBound(c.name) +
         stringBound(c.restriction) + (zone ? zone_files_[c.index].size() : 0);
}

bool VerdictLineWriter::writeCheck(Cursor& out, const Check& c) const {
  const bool box = c.level == Level::kCorridor || c.level == Level::kAirspace;
  const bool zone = c.level == Level::kZone || c.level == Level::kKeepIn;
  out.put('{');
  if (box) {
    if (c.across_joint) out.literal("\"across_joint\":true,\"hal_m\":"); else out.literal("\"across_joint\":false,\"hal_m\":");
    out.text(limits_text_[c.level == Level::kCorridor ? 0 : 1].first);
    out.put(',');
  } else if (c.level != Level::kKeepIn) {
    out.literal("\"clearance_m\":");
    if (c.clearance_m) putMetres(out, *c.clearance_m); else out.literal("null");
    if (c.exact) out.literal(",\"exact\":true,"); else out.literal(",\"exact\":false,");
  }
  if (zone) {
    if (!zone_file_ok_[c.index]) return false;
    out.literal("\"file\":");
    out.text(zone_files_[c.index]);
    out.put(',');
  }
  out.literal("\"level\":");
  putWord(out, levelName(c.level));
  out.literal(",\"margin_h_m\":");
  putMetres(out, c.margin_h_m);
  out.literal(",\"margin_v_m\":");
  putMetres(out, c.margin_v_m);
  out.put(',');
  if (zone) {
    out.literal("\"name\":");
    if (!putString(out, c.name)) return false;
    out.literal(",\"restriction\":");
    if (!putString(out, c.restriction)) return false;
    out.put(',');
  }
  if (box) {
    out.literal("\"segment\":");
    putUnsigned(out, c.index);
    out.put(',');
  }
  out.literal("\"subject\":");
  if (!putString(out, c.subject)) return false;
  if (box) {
    out.literal(",\"val_m\":");
    out.text(limits_text_[c.level == Level::kCorridor ? 0 : 1].second);
  }
  out.literal(",\"verdict\":");
  putWord(out, verdictWord(c.level, c.verdict));
  out.put('}');
  return true;
}

bool VerdictLineWriter::append(std::string& out, std::string_view id_json, const maps::GpsTime& t0,
                               const maps::GpsTime& t1, std::size_t line, const FenceVerdict& v) const {
  const TimeText from(t0);
  const std::optional<TimeText> until = t1 - t0 > 0 ? std::optional<TimeText>(t1) : std::nullopt;
  std::size_t bound = kLineFixedBytes + id_json.size() + from.view().size() + (until ? until->view().size() : 0);
  for (const Check& c : v.checks) bound += checkBound(c) + 1;
  const std::size_t start = out.size();
  out.resize(start + bound);
  Cursor text(out.data() + start);
  if (!writeLine(text, id_json, from.view(), until ? until->view() : std::string_view(), line, v)) {
    out.resize(start);
    return false;
  }
  const auto used = static_cast<std::size_t>(text.at() - out.data());
  if (used > start + bound) std::abort();  // the bounds above are wrong: memory is already overwritten
  out.resize(used);
  return true;
}

bool VerdictLineWriter::writeLine(Cursor& out, std::string_view id_json, std::string_view from, std::string_view until,
                                  std::size_t line, const FenceVerdict& v) const {
  out.literal("{\"checks\":[");
  for (std::size_t i = 0; i < v.checks.size(); ++i) {
    if (i > 0) out.put(',');
    if (!writeCheck(out, v.checks[i])) return false;
  }
  out.literal("],");
  if (!id_json.empty()) {
    out.literal("\"id\":");
    out.text(id_json);
    out.put(',');
  }
  out.literal("\"line\":");
  putUnsigned(out, line);
  out.literal(",\"time\":\"");
  out.text(from);
  if (!until.empty()) {
    out.literal("\",\"until\":\"");
    out.text(until);
  }
  out.literal("\",\"verdict\":");
  putWord(out, verdictName(v.verdict));
  out.literal(",\"violated\":");
  if (v.violated) putWord(out, levelName(*v.violated)); else out.literal("null");
  out.literal("}\n");
  return true;
}

}  // namespace skylane::geofence
