#include "geofence/verdict_writer.hpp"

#include "maps/decimal_text.hpp"
#include "maps/json_numbers.hpp"


#include <charconv>
#include <cmath>

namespace skylane::geofence {
namespace {

/// maps::metresOrNull as its JSON text.
void appendMetres(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buf[maps::kRoundedMaxChars];
  out.append(buf, maps::jsonTextOfMillimetres(buf, maps::roundToMm(v)));
}

void appendUnsigned(std::string& out, std::size_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
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

/// Appends the escaped form of c (a control character, '"' or '\\'), as nlohmann writes it.
void appendEscape(std::string& out, unsigned char c) {
  static constexpr char kHex[] = "0123456789abcdef";
  switch (c) {
    case '\b': out += "\\b"; return;
    case '\t': out += "\\t"; return;
    case '\n': out += "\\n"; return;
    case '\f': out += "\\f"; return;
    case '\r': out += "\\r"; return;
    case '"': out += "\\\""; return;
    case '\\': out += "\\\\"; return;
    default: {
      const char esc[] = {'\\', 'u', '0', '0', kHex[c >> 4], kHex[c & 15]};
      out.append(esc, sizeof esc);
    }
  }
}

/// A JSON string as nlohmann's dump(-1) writes it (ensure_ascii off: UTF-8 as it is; \b \t \n
/// \f \r \" \\ and \u00xx for the other control characters); false on invalid UTF-8. Runs of
/// plain characters are appended whole.
bool appendString(std::string& out, std::string_view s) {
  out += '"';
  for (std::size_t i = 0; i < s.size();) {
    std::size_t run = i;
    while (run < s.size() && plainAscii(static_cast<unsigned char>(s[run]))) ++run;
    out.append(s.data() + i, run - i);
    if (run == s.size()) break;
    i = run;
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      appendEscape(out, c);
      ++i;
      continue;
    }
    const std::size_t n = utf8Length(s, i);
    if (n == 0) return false;
    out.append(s.data() + i, n);
    i += n;
  }
  out += '"';
  return true;
}

/// `"key":` (keys are plain ASCII).
void appendKey(std::string& out, std::string_view key) {
  out += '"';
  out += key;
  out += "\":";
}

void appendTime(std::string& out, const maps::GpsTime& t) {
  char buf[maps::kRfc3339MaxChars];
  out += '"';
  if (const char* end = maps::formatRfc3339To(buf, t, 3)) {
    out.append(buf, static_cast<std::size_t>(end - buf));
  } else {
    out += maps::formatRfc3339(t, 3);
  }
  out += '"';
}

}  // namespace

VerdictLineWriter::VerdictLineWriter(const Fence& fence) {
  for (const Corridor* level : {&fence.level1(), &fence.level2()}) {
    std::string hal, val;
    appendMetres(hal, level->limits().hal_m);
    appendMetres(val, level->limits().val_m);
    limits_text_.push_back({hal, val});
  }
  for (const airspace::Zone& z : fence.zones()) {
    std::string file;
    zone_file_ok_.push_back(appendString(file, z.source));
    zone_files_.push_back(file);
  }
}

bool VerdictLineWriter::appendCheck(std::string& out, const Check& c) const {
  const bool box = c.level == Level::kCorridor || c.level == Level::kAirspace;
  const bool zone = c.level == Level::kZone || c.level == Level::kKeepIn;
  out += '{';
  if (box) {
    out += c.across_joint ? "\"across_joint\":true," : "\"across_joint\":false,";
    appendKey(out, "hal_m");
    out += limits_text_[c.level == Level::kCorridor ? 0 : 1].first;
    out += ',';
  } else if (c.level != Level::kKeepIn) {
    appendKey(out, "clearance_m");
    if (c.clearance_m) appendMetres(out, *c.clearance_m); else out += "null";
    out += c.exact ? ",\"exact\":true," : ",\"exact\":false,";
  }
  if (zone) {
    if (!zone_file_ok_[c.index]) return false;
    appendKey(out, "file");
    out += zone_files_[c.index];
    out += ',';
  }
  appendKey(out, "level");
  appendString(out, levelName(c.level));
  out += ",\"margin_h_m\":";
  appendMetres(out, c.margin_h_m);
  out += ",\"margin_v_m\":";
  appendMetres(out, c.margin_v_m);
  out += ',';
  if (zone) {
    appendKey(out, "name");
    if (!appendString(out, c.name)) return false;
    out += ",\"restriction\":";
    if (!appendString(out, c.restriction)) return false;
    out += ',';
  }
  if (box) {
    appendKey(out, "segment");
    appendUnsigned(out, c.index);
    out += ',';
  }
  appendKey(out, "subject");
  if (!appendString(out, c.subject)) return false;
  if (box) {
    out += ",\"val_m\":";
    out += limits_text_[c.level == Level::kCorridor ? 0 : 1].second;
  }
  out += ",\"verdict\":";
  appendString(out, verdictWord(c.level, c.verdict));
  out += '}';
  return true;
}

bool VerdictLineWriter::append(std::string& out, std::string_view id_json, const maps::GpsTime& t0,
                               const maps::GpsTime& t1, std::size_t line, const FenceVerdict& v) const {
  const std::size_t start = out.size();
  out += "{\"checks\":[";
  for (std::size_t i = 0; i < v.checks.size(); ++i) {
    if (i > 0) out += ',';
    if (!appendCheck(out, v.checks[i])) {
      out.resize(start);
      return false;
    }
  }
  out += "],";
  if (!id_json.empty()) {
    appendKey(out, "id");
    out += id_json;
    out += ',';
  }
  appendKey(out, "line");
  appendUnsigned(out, line);
  out += ",\"time\":";
  appendTime(out, t0);
  if (t1 - t0 > 0) {
    out += ",\"until\":";
    appendTime(out, t1);
  }
  out += ",\"verdict\":";
  appendString(out, verdictName(v.verdict));
  out += ",\"violated\":";
  if (v.violated) appendString(out, levelName(*v.violated)); else out += "null";
  out += "}\n";
  return true;
}

}  // namespace skylane::geofence
