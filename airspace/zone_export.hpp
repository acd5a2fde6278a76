#pragma once
/// \file
/// \brief Zones as normalised GeoJSON features (`skylane zones export`, the service's zone sets
/// and the web map): one feature per volume — its outline (a circle as a Point with `radius_m`),
/// identifier, name, restriction (KEEP_IN for a keep-in fence), the limits as given and resolved
/// to ellipsoidal and AMSL ranges, and when it applies.

#include "airspace/vertical.hpp"
#include "airspace/zone.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace skylane::airspace {

/// \brief The features of one zone (one per volume).
[[nodiscard]] std::vector<nlohmann::json> zoneFeatures(const Zone& z, const VerticalModel& model);

/// \brief A vertical limit as JSON: {as_given, reference, value_m, unlimited}.
[[nodiscard]] nlohmann::json limitJson(const VerticalLimit& l);

/// \brief A zone's applicability as JSON: [{permanent, start, end, schedule}].
[[nodiscard]] nlohmann::json applicabilityJson(const Zone& z);

}  // namespace skylane::airspace
