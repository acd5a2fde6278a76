#pragma once
/// \file
/// \brief `skylane fence check`: the verdict of one fix or of a stream of fixes against a
/// corridor file, zones and obstacles.

#include "geofence/fence.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace skylane::cli {

/// \brief Registers `fence` on `app`.
void addFenceCommands(CLI::App& app);

}  // namespace skylane::cli
