#pragma once
/// \file
/// \brief The one error type for malformed external input (files, JSON, rasters, command-line
/// values), shared by every module: it lives in the lowest one.

#include <stdexcept>
#include <string>

namespace skylane::maps {

/// \brief Longest part of an offending value that a message repeats (the rest is cut, "…").
inline constexpr std::size_t kMaxQuotedBytes = 100;

/// \brief `text` made safe to print on one line of a terminal: control characters (newlines,
/// escape sequences, NUL), C1 controls and bytes that are not well-formed UTF-8 are written as
/// escapes (\n, \t, \r, \xNN); cut after `max_bytes` of the input, marked "…". Text that is
/// already printable comes back unchanged (so applying it twice changes nothing).
[[nodiscard]] std::string printable(const std::string& text, std::size_t max_bytes = std::string::npos);

/// \brief Bad external input: names the source (file), the line (0 = not line-based), the
/// field (for JSON a path such as "features[2](LSZB003).geometry.layer.upper"), the offending
/// value and what was expected.
/// The message quotes every part through printable(), the value cut at kMaxQuotedBytes.
class ParseError : public std::runtime_error {
 public:
  ParseError(std::string source, int line, std::string field, std::string value,
             std::string expected);

  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] int line() const { return line_; }
  [[nodiscard]] const std::string& field() const { return field_; }

 private:
  std::string source_;
  int line_;
  std::string field_;
};

}  // namespace skylane::maps
