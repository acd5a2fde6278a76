#pragma once
/// \file
/// \brief `skylane track`: live corridor tracking of approved flights (planner/tracking/tracker.hpp)
/// from JSON lines, NMEA 0183 or a RINEX observation replay, events as JSON lines, state in SQLite.

#include <CLI/CLI.hpp>

namespace skylane::cli {

/// \brief Registers `track` on `app`.
void addTrackCommands(CLI::App& app);

}  // namespace skylane::cli
