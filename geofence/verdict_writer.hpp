#pragma once
/// \file
/// \brief `fence check`'s verdict line written straight into a reused buffer (docs/method.md
/// §6.6): the bytes nlohmann's dump() writes for fenceVerdictJson plus the fix's "id", "line",
/// "time" and "until" — members in its (sorted) order, numbers by its shortest round-trip
/// conversion (nlohmann::detail::to_chars, the one its serializer calls), strings escaped as it
/// escapes them — without building a JSON tree or allocating per line.

#include "geofence/fence.hpp"
#include "maps/time.hpp"

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace skylane::geofence {

namespace detail {
class TextCursor;  ///< verdict_writer.cpp: writes into space sized beforehand
}  // namespace detail

/// \brief Writes verdict lines for one fence (holds references to nothing: what it needs of the
/// fence is copied at construction).
class VerdictLineWriter {
 public:
  explicit VerdictLineWriter(const Fence& fence);

  /// \brief Appends one line and '\n' to `out`: the fix's `id_json` (verbatim JSON text; empty:
  /// no "id"), its times and `line` number, and the verdict. False, with `out` as it was, when
  /// a string is not valid UTF-8 (nlohmann's dump refuses it: the caller takes that path).
  [[nodiscard]] bool append(std::string& out, std::string_view id_json, const maps::GpsTime& t0, const maps::GpsTime& t1,
                            std::size_t line, const FenceVerdict& v) const;

 private:
  using Cursor = detail::TextCursor;
  /// Most bytes writeCheck writes for c.
  [[nodiscard]] std::size_t checkBound(const Check& c) const;
  [[nodiscard]] bool writeCheck(Cursor& out, const Check& c) const;
  /// The line, its times already as text (until empty: none).
  [[nodiscard]] bool writeLine(Cursor& out, std::string_view id_json, std::string_view from, std::string_view until,
                               std::size_t line, const FenceVerdict& v) const;

  std::vector<std::pair<std::string, std::string>> limits_text_;  ///< level 1, level 2: (HAL, VAL) as JSON
  std::vector<std::string> zone_files_;         ///< per zone: its file as a JSON string
  std::vector<bool> zone_file_ok_;              ///< per zone: its file is valid UTF-8
};

}  // namespace skylane::geofence
