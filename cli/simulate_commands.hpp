#pragma once
/// \file
/// \brief `skylane simulate`: a GNSS/INS flight with fault injection, scored against the truth
/// (per-epoch CSV, error and protection-level plots, Stanford diagrams), or a Monte Carlo batch.

#include <CLI/CLI.hpp>

namespace skylane::cli {

/// \brief Registers `simulate` on `app`.
void addSimulateCommands(CLI::App& app);

}  // namespace skylane::cli
