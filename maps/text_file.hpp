#pragma once
/// \file
/// \brief Reading input files: whole text files, and JSON documents whose syntax errors name
/// the line.

#include <nlohmann/json_fwd.hpp>

#include <string>

namespace skylane::maps {

/// \brief A ParseError naming `path` and `field` (an option such as "--input") when it is a
/// folder: a folder opens for reading and reads as empty.
void requireNotAFolder(const std::string& path, const std::string& field);

/// \brief The whole file as bytes; ParseError naming the file when it cannot be read.
[[nodiscard]] std::string readTextFile(const std::string& path);

/// \brief Deepest nesting of a JSON input file (GeoJSON's deepest, a MultiPolygon's ring inside
/// a GeometryCollection inside a feature, is 8; the error builder and the parser recurse per level).
inline constexpr int kMaxJsonFileDepth = 64;

/// \brief A ParseError naming `source`, the line and the limit when arrays and objects in `text`
/// nest deeper than `max_depth` (strings skipped).
void requireJsonDepth(const std::string& text, const std::string& source, int max_depth);

/// \brief Parses JSON text; a syntax error, nesting deeper than kMaxJsonFileDepth or a number
/// beyond a double's range becomes a ParseError naming `source` and the line.
[[nodiscard]] nlohmann::json parseJsonText(const std::string& text, const std::string& source);

/// \brief readTextFile + parseJsonText.
[[nodiscard]] nlohmann::json readJsonFile(const std::string& path);

}  // namespace skylane::maps
