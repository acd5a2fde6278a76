#pragma once
/// \file
/// \brief `skylane worker` (a NATS JetStream track or approve worker) and `skylane nats`
/// (set up the streams, request an approval, publish fixes, read events) — docs/nats.md.

#include <CLI/CLI.hpp>

namespace skylane::cli {

void addWorkerCommands(CLI::App& app);

}  // namespace skylane::cli
