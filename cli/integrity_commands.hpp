#pragma once
/// \file
/// \brief `skylane integrity …` sub-commands: pl, predict, spp.

#include <CLI/CLI.hpp>

namespace skylane::cli {

/// \brief Registers the integrity sub-commands on `app`.
void addIntegrityCommands(CLI::App& app);

}  // namespace skylane::cli
