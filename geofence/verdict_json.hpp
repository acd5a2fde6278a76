#pragma once
/// \file
/// \brief The one JSON form of a check and of a verdict (docs/method.md §6.5; numbers by the
/// rule of maps/json_numbers.hpp). Every output that shows a check — `fence check`, the tracker's
/// events, the approval report's samples — takes its fields from here, whole or in part.
///
/// A check: {"level", "verdict", "subject", "margin_h_m", "margin_v_m"} and, for the two box
/// levels, "segment" (the path segment whose piece decides) and "across_joint"; for zones and
/// keep-in, "name" and "restriction"; for zones and obstacles, "clearance_m" and "exact"
/// (decided by exact predicates). The verdict word is verdictWord: inside / outside for the
/// boxes and keep-in, clear / met for zones and obstacles. A verdict: {"verdict" (inside: the
/// volume lies in the space every check allows; outside; indeterminate), "violated" (the
/// deciding level, null when inside), "checks"}.

#include "geofence/fence.hpp"

#include <nlohmann/json.hpp>

#include <initializer_list>

namespace skylane::geofence {

void to_json(nlohmann::json& j, const Check& c);
void to_json(nlohmann::json& j, const FenceVerdict& v);

/// \brief The one form read back (a zone's or obstacle's index in its scene is not part of it:
/// 0). A null margin is an unlimited one (+∞).
/// \throws maps::ParseError naming the JSON path, the value and what was expected.
void from_json(const nlohmann::json& j, Check& c);
/// \brief As from_json(Check); `deciding` is the first check of the violated level whose verdict
/// is the verdict's.
void from_json(const nlohmann::json& j, FenceVerdict& v);

/// \brief A fence verdict as `fence check` writes it: the one form, and in each check what the
/// fence knows of it — the box levels' "hal_m" and "val_m", the zones' and keep-in's "file".
[[nodiscard]] nlohmann::json fenceVerdictJson(const FenceVerdict& v, const Fence& fence);

/// \brief Whether a check is of a box level (corridor or airspace) rather than a zone or obstacle.
[[nodiscard]] inline bool isBoxLevel(const Check& c) { return c.level == Level::kCorridor || c.level == Level::kAirspace; }

/// \brief The members `keys` of an object (a view of the one form), in nlohmann's order.
[[nodiscard]] nlohmann::json pickMembers(const nlohmann::json& object, std::initializer_list<const char*> keys);

}  // namespace skylane::geofence
