#pragma once
/// \file
/// \brief `skylane approve MISSION.json`: preflight route approval (planner/approval.hpp) with
/// the JSON report and a plot of the predicted protection levels along the route.

#include "cli/svg_plot.hpp"
#include "geofence/fence.hpp"
#include "maps/plane_frame.hpp"

#include <CLI/CLI.hpp>

#include <vector>

namespace skylane::cli {

/// \brief The zones (by status: counted and permanent, time-limited, authorised or open) and the
/// buildings of a mission, as map shapes.
[[nodiscard]] std::vector<MapShape> obstructionShapes(const geofence::Obstructions& ob, const maps::PlaneFrame& frame);

/// \brief Registers `approve` on `app`.
void addApproveCommands(CLI::App& app);

}  // namespace skylane::cli
