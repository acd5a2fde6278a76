#pragma once
/// \file
/// \brief `skylane plan export REPORT.json`: an approval report's (or a replan's) route and fence
/// as a QGroundControl plan file (link/qgc_plan.hpp).

#include <CLI/CLI.hpp>

namespace skylane::cli {

/// \brief Registers `plan export` on `app`.
void addPlanCommands(CLI::App& app);

}  // namespace skylane::cli
