#pragma once
/// \file
/// \brief Text-field readers for the fixed-width GNSS formats (RINEX, YUMA, SEM); their errors are
/// maps::ParseError.

#include "maps/parse_error.hpp"

#include <string>
#include <vector>

namespace skylane::integrity {

/// \brief Bad external input (maps/parse_error.hpp).
using maps::ParseError;

/// \brief Parses a Fortran-style real ("1.23D-04", "  .5E+01", "-0.1") from a fixed-width
/// field. Blank fields give `blank_value`. Throws ParseError naming the field otherwise.
[[nodiscard]] double parseFortranReal(const std::string& text, const std::string& source, int line,
                                      const std::string& field, double blank_value = 0.0);

/// \brief Parses an integer from a field (surrounding blanks allowed); blank → `blank_value`.
[[nodiscard]] int parseInt(const std::string& text, const std::string& source, int line,
                           const std::string& field, int blank_value = 0);

/// \brief An integer-valued real (RINEX and YUMA write integers as reals) in [lo, hi]; throws
/// ParseError naming the field when it is fractional or out of range.
[[nodiscard]] int integerField(double value, int lo, int hi, const std::string& source, int line,
                               const std::string& field);

/// \brief Substring that tolerates short lines (returns what exists, possibly empty).
[[nodiscard]] std::string field(const std::string& line, std::size_t pos, std::size_t len);

/// \brief Copy without leading and trailing blanks (space, tab, CR, LF).
[[nodiscard]] std::string trim(const std::string& s);

/// \brief Splits text into lines (LF or CRLF); line i of the file is element i − 1.
[[nodiscard]] std::vector<std::string> splitLines(const std::string& text);

/// \brief The header label of a RINEX line (columns 61–80, trimmed).
[[nodiscard]] inline std::string rinexLabel(const std::string& line) { return trim(field(line, 60, 20)); }

/// \brief RINEX 2 two-digit year: 80–99 → 19xx, 00–79 → 20xx (RINEX 2.11 §6.5).
[[nodiscard]] inline int rinexFullYear(int yy) { return yy < 80 ? 2000 + yy : (yy < 100 ? 1900 + yy : yy); }

}  // namespace skylane::integrity
