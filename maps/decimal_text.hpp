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

}  // namespace skylane::maps
