#pragma once
/// \file
/// \brief `skylane serve`: the approval and tracking service (service/service.hpp).

#include <CLI/CLI.hpp>

namespace skylane::cli {

void addServeCommands(CLI::App& app);

}  // namespace skylane::cli
