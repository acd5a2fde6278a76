#pragma once
/// \file
/// \brief A mission with the files it names, carried as one JSON document over NATS: an approval
/// request (the mission and its zone, orbit, buildings and .plan files) and, once approved, the
/// same with the approval report — what a track worker on another machine needs to track the
/// flight. Files are text (JSON, almanacs, RINEX); a terrain raster is not carried (a mission
/// for the workers gives `ground_amsl_m`).
///
/// Form: {"mission": "<mission.json as text>", "files": {"files/0-zones.json": "<text>", …},
///        "report": "<report.json as text>"} — texts kept byte for byte, so the report's SHA-256
/// of the mission still holds where the bundle is unpacked.

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <map>
#include <string>

namespace skylane::service {

/// \brief A mission, its files by relative name, and (after approval) the report.
struct ApprovalBundle {
  std::string mission;                       ///< mission.json as text, its file names relative
  std::map<std::string, std::string> files;  ///< relative name → content
  std::string report;                        ///< report.json as text; empty before approval
};

/// \brief Reads a mission file and every file it names; the names become `files/<i>-<name>`.
/// \throws maps::ParseError naming the mission, the field and what was expected (a terrain
/// raster, an unreadable file).
[[nodiscard]] ApprovalBundle packMission(const std::string& mission_path);
/// \brief The bundle as JSON text.
[[nodiscard]] std::string bundleText(const ApprovalBundle& b);
/// \brief A bundle from JSON text. \throws maps::ParseError naming `source`, the field and what
/// was expected (a file name that is not relative and inside the bundle's folder).
[[nodiscard]] ApprovalBundle parseBundle(const std::string& text, const std::string& source);
/// \brief Writes mission.json, the files and report.json (when there is one) into `dir`.
void unpackBundle(const ApprovalBundle& b, const std::filesystem::path& dir);

}  // namespace skylane::service
