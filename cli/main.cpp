/// \file
/// \brief The `skylane` command: parse, call, print; errors → one line on stderr, exit 2.

#include "cli/approve_commands.hpp"
#include "cli/fence_commands.hpp"
#include "cli/integrity_commands.hpp"
#include "cli/plan_commands.hpp"
#include "cli/serve_commands.hpp"
#include "cli/simulate_commands.hpp"
#include "cli/skymask_commands.hpp"
#include "cli/track_commands.hpp"
#include "cli/worker_commands.hpp"
#include "cli/zones_commands.hpp"
#include "integrity/gnss/parse_error.hpp"
#include "maps/atomic_file.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <stdexcept>

/// `status`, or 2 with a message when a write to standard output failed (a full disk, /dev/full).
static int afterStandardOutput(int status) {
  try {
    skylane::maps::flushStandardOutput();
  } catch (const skylane::maps::OutputError& e) {
    std::cerr << "skylane: error: " << e.what() << "\n";
    return 2;
  }
  return status;
}

int main(int argc, char** argv) {
  CLI::App app{"skylane: airspace geofence and path-planning integrity planner for unmanned aircraft"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("skylane ") + SKYLANE_VERSION);
  skylane::cli::addIntegrityCommands(app);
  skylane::cli::addZonesCommands(app);
  skylane::cli::addSkyMaskCommands(app);
  skylane::cli::addFenceCommands(app);
  skylane::cli::addSimulateCommands(app);
  skylane::cli::addApproveCommands(app);
  skylane::cli::addTrackCommands(app);
  skylane::cli::addPlanCommands(app);
  skylane::cli::addServeCommands(app);
  skylane::cli::addWorkerCommands(app);
  skylane::maps::watchStandardOutput();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print what was asked for; a bad option or option file is one line
    // naming the option and the value (CLI11's own message, e.g. "mission: File does not
    // exist: m.json"), as every other bad input (no "Run with --help" second line).
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "skylane: error: " << skylane::maps::printable(e.what()) << "\n";
    return 2;
  } catch (const skylane::cli::ExitStatus& e) {
    return afterStandardOutput(e.status);
  } catch (const skylane::integrity::ParseError& e) {
    std::cerr << "skylane: error: " << e.what() << "\n";
    return 2;
  } catch (const skylane::maps::OutputError& e) {
    std::cerr << "skylane: error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "skylane: error: " << skylane::maps::printable(e.what()) << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "skylane: internal error: " << skylane::maps::printable(e.what()) << "\n";
    return 1;
  }
  return afterStandardOutput(0);
}
