#include "maps/parse_error.hpp"

#include <utility>

namespace skylane::maps {
namespace {

/// Longest field name (a JSON path) a message repeats.
constexpr std::size_t kMaxFieldBytes = 200;

/// Length of the well-formed UTF-8 sequence at text[i] (1–4), 0 when the bytes there are not
/// one (RFC 3629 §4: no overlong forms, no surrogates, nothing above U+10FFFF).
std::size_t utf8Length(const std::string& text, std::size_t i) {
  const auto byte = [&text](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the second byte's range
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (i + n > text.size() || byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return n;
}

/// One byte as an escape.
std::string escaped(unsigned char c) {
  if (c == '\n') return "\\n";
  if (c == '\r') return "\\r";
  if (c == '\t') return "\\t";
  static const char kHex[] = "0123456789abcdef";
  return std::string("\\x") + kHex[c >> 4] + kHex[c & 0xF];
}

std::string describe(const std::string& source, int line, const std::string& field,
                     const std::string& value, const std::string& expected) {
  std::string msg = printable(source);
  if (line > 0) msg += ":" + std::to_string(line);
  msg += ": field '" + printable(field, kMaxFieldBytes) + "'";
  msg += value.empty() ? std::string(" is missing") : ": got '" + printable(value, kMaxQuotedBytes) + "'";
  msg += ", expected " + printable(expected);
  return msg;
}

}  // namespace

std::string printable(const std::string& text, std::size_t max_bytes) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    if (i >= max_bytes) {
      out += "…";
      break;
    }
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const std::size_t n = utf8Length(text, i);
    // C1 controls (U+0080–U+009F, "\xc2\x80"–"\xc2\x9f") are escape sequences to some terminals.
    const bool c1 = n == 2 && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0;
    if ((n == 1 && c >= 0x20 && c != 0x7F) || (n > 1 && !c1)) {
      out.append(text, i, n);
      i += n;
    } else {
      out += escaped(c);
      ++i;
    }
  }
  return out;
}

ParseError::ParseError(std::string source, int line, std::string field, std::string value,
                       std::string expected)
    : std::runtime_error(describe(source, line, field, value, expected)),
      source_(std::move(source)),
      line_(line),
      field_(std::move(field)) {}

}  // namespace skylane::maps
