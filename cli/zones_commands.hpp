#pragma once
/// \file
/// \brief `skylane zones …` sub-commands: validate, at, export.

#include <CLI/CLI.hpp>

namespace skylane::cli {

/// \brief Ends the command with this exit status after its output is written (for example
/// `zones validate` finding an invalid zone: the report is the output, the status says so).
struct ExitStatus {
  explicit ExitStatus(int s) : status(s) {}
  int status;
};

/// \brief Registers the zones sub-commands on `app`.
void addZonesCommands(CLI::App& app);

}  // namespace skylane::cli
