#pragma once
/// \file
/// \brief A JSON value together with its path in the file, for loaders whose errors must name
/// the file, the feature and the field (zones, buildings).

#include "maps/parse_error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <initializer_list>
#include <string>

namespace skylane::maps {

/// \brief Longest text kept from a JSON value quoted in an error message.
inline constexpr std::size_t kJsonQuoteChars = 60;

/// \brief The value as text for a message: strings as they are, the rest dumped; cut at
/// kJsonQuoteChars.
[[nodiscard]] inline std::string quoteJson(const nlohmann::json& j) {
  std::string s = j.is_string() ? j.get<std::string>() : j.dump();
  if (s.size() > kJsonQuoteChars) s = s.substr(0, kJsonQuoteChars) + "…";
  return s.empty() ? std::string("\"\"") : s;
}

/// \brief Deepest nesting of a JSON-lines record (a fix needs 3).
inline constexpr int kMaxJsonLineDepth = 32;

/// \brief One line of a JSON-lines stream parsed; `source` names it ("file:line").
/// \throws ParseError quoting the line's start and the parser's message.
[[nodiscard]] inline nlohmann::json parseJsonLine(const std::string& text, const std::string& source) {
  // Nesting is bounded: the serializer that quotes a value in an error recurses per level.
  const auto bounded = [&source](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxJsonLineDepth) {
      throw ParseError(source, 0, "$", "", "JSON nested at most " + std::to_string(kMaxJsonLineDepth) + " levels deep");
    }
    return true;
  };
  try {
    return nlohmann::json::parse(text, bounded);
  } catch (const nlohmann::json::parse_error& e) {
    throw ParseError(source, 0, "$", text.substr(0, kJsonQuoteChars), std::string("one JSON object per line (") + e.what() + ")");
  } catch (const nlohmann::json::out_of_range& e) {
    throw ParseError(source, 0, "$", text.substr(0, kJsonQuoteChars),
                     std::string("numbers within a double's range (") + e.what() + ")");
  }
}

/// \brief A JSON value with its path in the file (e.g. "features[3].properties.height");
/// every accessor throws ParseError naming the source, the path, the value and what was
/// expected. Holds references: the document and the source outlive it.
struct JsonNode {
  const nlohmann::json& j;
  std::string path;
  const std::string& source;

  /// \brief Throws ParseError for this value.
  [[noreturn]] void fail(const std::string& expected) const {
    throw ParseError(source, 0, path, j.is_null() ? "null" : quoteJson(j), expected);
  }
  /// \brief An object whose members are all among `known` (an error naming the first other one
  /// and listing the known ones).
  void requireKnownFields(std::initializer_list<const char*> known) const {
    if (!j.is_object()) fail("an object");
    for (const auto& item : j.items()) {
      bool ok = false;
      for (const char* k : known) ok = ok || item.key() == k;
      if (ok) continue;
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      throw ParseError(source, 0, path + "." + item.key(), quoteJson(item.value()),
                       "no such field here (an unknown field; known: " + list + ")");
    }
  }
  /// \brief An object with a non-null member `key`.
  [[nodiscard]] bool has(const char* key) const { return j.is_object() && j.contains(key) && !j.at(key).is_null(); }
  /// \brief The member `key` (an error when this is not an object or the key is absent).
  [[nodiscard]] JsonNode at(const char* key) const {
    if (!j.is_object()) fail("an object");
    if (!j.contains(key)) throw ParseError(source, 0, path + "." + key, "", "a value");
    return {j.at(key), path + "." + key, source};
  }
  /// \brief The value at `key`, or a null value with that path when the key is absent.
  [[nodiscard]] JsonNode orNull(const char* key) const {
    static const nlohmann::json kNull;
    return has(key) ? at(key) : JsonNode{kNull, path + "." + key, source};
  }
  /// \brief Element i of an array.
  [[nodiscard]] JsonNode item(std::size_t i) const { return {j.at(i), path + "[" + std::to_string(i) + "]", source}; }
  /// \brief The array itself (an error when not an array).
  [[nodiscard]] const nlohmann::json& array() const {
    if (!j.is_array()) fail("an array");
    return j;
  }
  /// \brief A string.
  [[nodiscard]] std::string str() const {
    if (!j.is_string()) fail("a string");
    return j.get<std::string>();
  }
  /// \brief A finite number.
  [[nodiscard]] double number() const {
    if (!j.is_number()) fail("a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail("a finite number");
    return v;
  }
  /// \brief A number in [lo, hi]; the error names the range and `unit` ("m", "Hz").
  [[nodiscard]] double numberIn(double lo, double hi, const std::string& unit) const {
    const double v = number();
    if (!(v >= lo && v <= hi)) {
      char range[96];
      std::snprintf(range, sizeof range, "a number in [%g, %g] %s", lo, hi, unit.c_str());
      fail(range);
    }
    return v;
  }
  /// \brief A number in (0, hi]; the error names the bound and `unit`.
  [[nodiscard]] double positiveUpTo(double hi, const std::string& unit) const {
    const double v = number();
    if (!(v > 0.0 && v <= hi)) {
      char range[96];
      std::snprintf(range, sizeof range, "a number > 0 and ≤ %g %s", hi, unit.c_str());
      fail(range);
    }
    return v;
  }
  /// \brief true or false.
  [[nodiscard]] bool boolean() const {
    if (!j.is_boolean()) fail("true or false");
    return j.get<bool>();
  }
};

}  // namespace skylane::maps
