#include "maps/text_file.hpp"

#include "maps/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace skylane::maps {

void requireNotAFolder(const std::string& path, const std::string& field) {
  struct stat info {};
  // (A folder opens for reading and reads as empty: "empty" or "invalid JSON" would hide why.)
  if (::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) throw ParseError(path, 0, field, "a folder", "a file");
}

std::string readTextFile(const std::string& path) {
  requireNotAFolder(path, "file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "file", "", "a readable file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

/// 1 + the newlines before byte `upto`.
int lineAt(const std::string& text, std::size_t upto) {
  upto = std::min(upto, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(upto), '\n'));
}

/// The byte where the nesting of arrays and objects first exceeds `limit` (strings skipped),
/// or npos. A linear scan before parsing: nlohmann's parser and serializer recurse per level.
std::size_t tooDeepAt(const std::string& text, int limit) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return i;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::string::npos;
}

}  // namespace

void requireJsonDepth(const std::string& text, const std::string& source, int max_depth) {
  const std::size_t at = tooDeepAt(text, max_depth);
  if (at == std::string::npos) return;
  throw ParseError(source, lineAt(text, at), "(JSON nesting)", text.substr(at, 16),
                   "JSON nested at most " + std::to_string(max_depth) + " levels deep");
}

nlohmann::json parseJsonText(const std::string& text, const std::string& source) {
  requireJsonDepth(text, source, kMaxJsonFileDepth);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond a double's range ("number overflow parsing '1e400'"): name it and its line.
    const std::string what = e.what();
    const auto q0 = what.find('\''), q1 = what.rfind('\'');
    const std::string number = q0 != std::string::npos && q1 > q0 ? what.substr(q0 + 1, q1 - q0 - 1) : what;
    const std::size_t at = text.find(number);
    throw ParseError(source, at == std::string::npos ? 0 : lineAt(text, at), "(JSON number)", number,
                     "a number within a double's range (±1.8e308)");
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann reports a byte offset; turn it into a line number.
    const int line = lineAt(text, e.byte);
    const std::string what = e.what();
    const auto colon = what.rfind(": ");
    throw ParseError(source, line, "(JSON syntax)", colon == std::string::npos ? what : what.substr(colon + 2),
                     "valid JSON (RFC 8259)");
  }
}

nlohmann::json readJsonFile(const std::string& path) { return parseJsonText(readTextFile(path), path); }

}  // namespace skylane::maps
