#pragma once
/// \file
/// \brief The events of the tracking engine: {"event": type, "flight", "time", …}. A `fix` event
/// holds a FixRecord (typed: its JSON is made only when it is written); the others their fields
/// in `body`. One serialisation: toJson() (read back by from_json); jsonLine() is the same object written without
/// building it, for the stream's hot path (a test checks both agree for every event kind).

#include "geofence/fence.hpp"
#include "integrity/gnss/satellite_id.hpp"
#include "maps/time.hpp"
#include "planner/tracking/track_fix.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::planner {

/// \brief What a `fix` event says.
struct FixRecord {
  std::size_t line = 0;
  double lat_rad = 0.0, lon_rad = 0.0, h_ell_m = 0.0;  ///< the position checked (skylane's own with raw ranges)
  double hpl_m = 0.0, vpl_m = 0.0;
  PlSource pl_source = PlSource::kOnboard;
  std::optional<bool> fault_detected;  ///< raw ranges: the first pass's detection (GNSS/INS: its FDE's)
  std::vector<integrity::SatId> excluded;  ///< left out of the position (GNSS/INS FDE, a rerun)
  std::optional<bool> ins_degraded;    ///< GNSS/INS: GNSS alone after an IMU fault (fault-mode flow)
  geofence::FenceVerdict verdict;
  int route_version = 0;
  bool rerun = false;
  std::string note;
};

/// \brief One event of the output stream.
struct TrackEvent {
  const char* type = "";
  std::string flight;  ///< empty: none (an unreadable record)
  std::optional<maps::GpsTime> time;
  std::optional<FixRecord> fix;
  nlohmann::json body;  ///< null until a field is set (a `fix` event needs none: no allocation per fix)
  /// \brief A field of the body.
  nlohmann::json& operator[](const char* key) { return body[key]; }
  [[nodiscard]] bool is(const char* t) const { return std::string_view(type) == t; }
  /// \brief The event as one JSON object.
  [[nodiscard]] nlohmann::json toJson() const;
  /// \brief toJson() written on one line, without building the object for a `fix` event (the
  /// same members and numbers). Bytes that are not UTF-8 are replaced.
  [[nodiscard]] std::string jsonLine() const;
  /// \brief jsonLine() appended to `out` (a buffer reused from event to event allocates only
  /// when it grows).
  void appendJsonLine(std::string& out) const;
};

/// \brief An event of `type` for `flight` at `t` with an empty body.
[[nodiscard]] TrackEvent trackEvent(const char* type, const std::string& flight, const maps::GpsTime& t);

/// \brief A `rejected_input` event: a record of `source` (line `line`, 0: none) that could not be taken, and why.
[[nodiscard]] TrackEvent rejectedInputEvent(const std::string& source, std::size_t line, const std::string& why);

/// \brief An `input_dropped` event: `count` datagrams of UDP input `source` dropped by the kernel
/// (its receive buffer was full) since the last such event, `total` since the input was opened.
[[nodiscard]] TrackEvent inputDroppedEvent(const std::string& source, std::uint64_t count, std::uint64_t total);

/// \brief FixRecord's members as JSON (merged into the `fix` event's object).
void to_json(nlohmann::json& j, const FixRecord& f);

/// \brief A `fix` event's members read back. The event shows a part of each check (box levels:
/// verdict, margins, segment; zones and obstacles: level, subject, verdict, clearance): the
/// rest takes its default (no joint, not exact, unlimited margins of a zone).
/// \throws maps::ParseError naming the JSON path, the value and what was expected.
void from_json(const nlohmann::json& j, FixRecord& f);

/// \brief An event read back from its JSON form: toJson() of the result is the input.
/// \throws maps::ParseError for an unknown event type or a bad member.
void from_json(const nlohmann::json& j, TrackEvent& e);

}  // namespace skylane::planner
