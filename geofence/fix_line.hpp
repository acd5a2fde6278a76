#pragma once
/// \file
/// \brief The plain form of a fix line, read without allocating (the `fence check` stream's fast
/// path; docs/method.md §6.6).
///
/// A stream of fixes is almost always written by a program: one flat object whose members are
/// the fields of geofence/fix.hpp, numbers, strings without escapes, an "id" that is a plain
/// string or an integer. readPlainFixLine reads exactly that form and checks every value the way
/// parseFix does. Anything else — another member, a duplicate, an escape, a non-ASCII byte, a
/// number JSON writes otherwise, a value parseFix would refuse, a syntax error — is "not plain":
/// the caller parses the line with maps::parseJsonLine and parseFix, which accept what JSON
/// allows and word the errors. So the fast path never writes an error of its own, and what it
/// accepts is what parseFix reads (the fence fuzz target checks both on every input).

#include "maps/time.hpp"

#include <string_view>

namespace skylane::geofence {

/// \brief One fix as readPlainFixLine read it.
struct PlainFix {
  /// The id's JSON text as written: a string without escapes or non-ASCII bytes (quotes
  /// included) or an integer of at most 18 digits, which nlohmann writes back byte for byte;
  /// empty when the line has no id.
  std::string_view id_json;
  maps::GpsTime t0;  ///< "time"
  maps::GpsTime t1;  ///< "until", else t0
  double lat_rad = 0, lon_rad = 0, h_ell_m = 0;
  double hpl_m = 0, vpl_m = 0;
};

/// \brief Reads `text` if it is a fix in the plain form (see the file comment) into `out`; false
/// when it is not (the caller then takes the general path, which reports any error).
[[nodiscard]] bool readPlainFixLine(std::string_view text, PlainFix& out);

}  // namespace skylane::geofence
