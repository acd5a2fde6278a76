#pragma once
/// \file
/// \brief SHA-256 digests of input files (FIPS 180-4, through OpenSSL's EVP interface), so that
/// a report names exactly which inputs it was made from and can be audited and replayed.

#include <string>

namespace skylane::maps {

/// \brief Lower-case hex SHA-256 of a byte string.
[[nodiscard]] std::string sha256Hex(const std::string& bytes);

/// \brief Lower-case hex SHA-256 of a file's contents.
/// \throws ParseError naming the file when it cannot be read.
[[nodiscard]] std::string fileSha256Hex(const std::string& path);

}  // namespace skylane::maps
