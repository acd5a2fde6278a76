#include "maps/text_file.hpp"

#include "maps/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace skylane::maps {

std::string readTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "file", "", "a readable file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json parseJsonText(const std::string& text, const std::string& source) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann reports a byte offset; turn it into a line number.
    const std::size_t upto = std::min<std::size_t>(e.byte, text.size());
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(upto), '\n'));
    const std::string what = e.what();
    const auto colon = what.rfind(": ");
    throw ParseError(source, line, "(JSON syntax)", colon == std::string::npos ? what : what.substr(colon + 2),
                     "valid JSON (RFC 8259)");
  }
}

nlohmann::json readJsonFile(const std::string& path) { return parseJsonText(readTextFile(path), path); }

}  // namespace skylane::maps
