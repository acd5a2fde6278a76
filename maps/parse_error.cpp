#include "maps/parse_error.hpp"

#include <utility>

namespace skylane::maps {
namespace {

std::string describe(const std::string& source, int line, const std::string& field,
                     const std::string& value, const std::string& expected) {
  std::string msg = source;
  if (line > 0) msg += ":" + std::to_string(line);
  msg += ": field '" + field + "'";
  msg += value.empty() ? std::string(" is missing") : ": got '" + value + "'";
  msg += ", expected " + expected;
  return msg;
}

}  // namespace

ParseError::ParseError(std::string source, int line, std::string field, std::string value,
                       std::string expected)
    : std::runtime_error(describe(source, line, field, value, expected)),
      source_(std::move(source)),
      line_(line),
      field_(std::move(field)) {}

}  // namespace skylane::maps
