#pragma once
/// \file
/// \brief The shortest decimal text of a value already rounded to a number of decimals
/// (maps/json_numbers.hpp: metres to 3, degrees to 8), written from its integer count of units.
///
/// For 1e-3 ≤ |v| < 1e5 a value n / 10^d (the double nearest that decimal) has exactly one
/// shortest decimal that reads back as it: n / 10^d without its trailing zeros — any other
/// decimal of as few digits is another multiple of 10^-d, and those are farther apart than the
/// doubles there. In that range the plain form is never longer than the exponent form, so the
/// text is the one std::to_chars(first, last, v) writes (tests/maps/decimal_text_test.cpp
/// compares the two). Any other value is written by std::to_chars.

namespace skylane::maps {

/// \brief Longest text toCharsRounded writes.
inline constexpr int kRoundedMaxChars = 32;

/// \brief Writes v as std::to_chars(first, first + kRoundedMaxChars, v) does, quickly when v is a
/// value rounded to `decimals` (0–8) decimal places; returns the end of the text.
[[nodiscard]] char* toCharsRounded(char* first, double v, int decimals);

/// \brief Writes v, a length rounded to the millimetre (roundToMm), as nlohmann's dump() does:
/// its Grisu2 digits with ".0" after an integer. For 1e-3 ≤ |v| < 1e5 the digits are the
/// shortest (every millimetre count below 10^8 was compared with nlohmann's conversion, and the
/// tests compare every count to 2 km and random ones), so they are written from the count;
/// any other value goes through nlohmann's conversion. Returns the end of the text.
[[nodiscard]] char* jsonTextOfMillimetres(char* first, double v);

}  // namespace skylane::maps
