#pragma once
/// \file
/// \brief The one error type for malformed external input (files, JSON, rasters, command-line
/// values), shared by every module: it lives in the lowest one.

#include <stdexcept>
#include <string>

namespace skylane::maps {

/// \brief Bad external input: names the source (file), the line (0 = not line-based), the
/// field (for JSON a path such as "features[2](LSZB003).geometry.layer.upper"), the offending
/// value and what was expected.
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
