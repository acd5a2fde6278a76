#include "integrity/gnss/parse_error.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace skylane::integrity {

std::string trim(const std::string& s) {
  const char* ws = " \t\r\n";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

int integerField(double value, int lo, int hi, const std::string& source, int line,
                 const std::string& field_name) {
  if (!(value >= lo && value <= hi) || value != std::floor(value)) {
    std::ostringstream v;
    v << value;
    throw ParseError(source, line, field_name, v.str(),
                     "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return static_cast<int>(value);
}

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::size_t len = end - start;
    if (len > 0 && text[start + len - 1] == '\r') --len;
    lines.emplace_back(text, start, len);
    start = end + 1;
  }
  return lines;
}

std::string field(const std::string& line, std::size_t pos, std::size_t len) {
  if (pos >= line.size()) return {};
  return line.substr(pos, len);
}

double parseFortranReal(const std::string& text, const std::string& source, int line,
                        const std::string& field_name, double blank_value) {
  const std::string original = trim(text);
  if (original.empty()) return blank_value;
  std::string t = original;
  for (char& c : t) {
    if (c == 'D' || c == 'd') c = 'E';
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end == t.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    throw ParseError(source, line, field_name, original, "a finite real number");
  }
  return v;
}

int parseInt(const std::string& text, const std::string& source, int line,
             const std::string& field_name, int blank_value) {
  const std::string t = trim(text);
  if (t.empty()) return blank_value;
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(t.c_str(), &end, 10);
  if (end == t.c_str() || *end != '\0' || errno == ERANGE || v < -2147483647L || v > 2147483647L) {
    throw ParseError(source, line, field_name, t, "an integer");
  }
  return static_cast<int>(v);
}

}  // namespace skylane::integrity
