#pragma once
/// \file
/// \brief `skylane approve MISSION.json`: preflight route approval (planner/approval.hpp) with
/// the JSON report and a plot of the predicted protection levels along the route.

#include <CLI/CLI.hpp>

namespace skylane::cli {

/// \brief Registers `approve` on `app`.
void addApproveCommands(CLI::App& app);

}  // namespace skylane::cli
