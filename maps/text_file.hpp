#pragma once
/// \file
/// \brief Reading input files: whole text files, and JSON documents whose syntax errors name
/// the line.

#include <nlohmann/json_fwd.hpp>

#include <string>

namespace skylane::maps {

/// \brief The whole file as bytes; ParseError naming the file when it cannot be read.
[[nodiscard]] std::string readTextFile(const std::string& path);

/// \brief Parses JSON text; a syntax error becomes a ParseError naming `source` and the line.
[[nodiscard]] nlohmann::json parseJsonText(const std::string& text, const std::string& source);

/// \brief readTextFile + parseJsonText.
[[nodiscard]] nlohmann::json readJsonFile(const std::string& path);

}  // namespace skylane::maps
